"""Studies built on the harness: the Solar Boat study and its MuJoCo model."""
