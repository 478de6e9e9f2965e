"""Sweeps of suspension configurations: a space of rigs (``space.py``), how each axis changes a rig
(``axes.py``), what is computed per configuration (``evaluate.py``) and the grid run in chunks on local
processes or a Dask cluster (``run.py``)."""
