"""Seed 001 (shared/seeds/001_5cee7e593b8d21bf.txt): a double-arm pendulum with a counterweight and
Rayleigh friction, in a vertical plane.

* :mod:`.params` -- the parameter file ``models/seed001/params.toml`` and the five rigid parts;
* :mod:`.seed` -- the seed's equations exactly as printed (constants A..E, f, g, special case),
  and :func:`.seed.g_fixed`, the repair of the one formula that fails;
* :mod:`.chain` -- the same pendulum derived independently, as a planar two-link chain;
* :mod:`.integrate` -- the seed's RK4 and scipy's DOP853;
The MuJoCo side (the model built from the parameters, and its runs with the seed's friction applied
as generalized forces) is :mod:`validate.engines.seed001_mjcf` and :mod:`validate.engines.seed001_mujoco`:
this package holds only the hand-derived equations.
"""
