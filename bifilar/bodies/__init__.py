"""Bodies: composite mass properties from parts, and the Solar Boat with its suspension."""
