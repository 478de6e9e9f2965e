"""The bifilar pendulum: rig files, models of motion, identification, bodies and the other seeds.

What a script uses is here by name; the rest is in the subpackages (``docs/architecture.md``): a rig
file read and checked (:func:`load_rig`, :func:`rig_from_dict`, a :class:`Rig`, a :class:`RigError`
naming file, field and problem), its rest pose (:func:`rest_pose`) and linear modes
(:func:`linearize`), the period of the mode that turns about a body axis, linear
(:func:`linear_period`) or at a finite amplitude from the Kane model (:func:`simulated_period`), a
moment of inertia from a measured period (:func:`identify`, an :class:`Identified`), a record read and
fitted (:func:`read_record`, :func:`fit_oscillation`), records turned into one moment
(:func:`identify_records`), and the whole tensor from a file of hangings (:func:`read_hangings`,
:func:`fit_hangings`). More of the identification: :mod:`bifilar.identification`.

The bench plate of ``models/rigs/`` (run from the project's folder), its yaw period and the moment
about z that a measured 1.5 s gives:

>>> import bifilar
>>> rig = bifilar.load_rig("models/rigs/bench_plate.toml")
>>> print(f"{bifilar.linear_period(rig, 'z'):.4f} s")
2.0058 s
>>> print([mode.motion for mode in bifilar.linearize(rig).modes])
['sway y', 'sway x', 'yaw', 'tilt']
>>> found = bifilar.identify(rig, "z", period=1.5)
>>> print(f"{found.moment:.5f} kg m^2 (the file says {rig.inertia[2, 2]:.5f})")
0.08389 kg m^2 (the file says 0.15000)

The names load on first use (PEP 562), so that ``import bifilar`` stays cheap for the command line:
it only points numba's cache at the user's cache folder (:mod:`bifilar.jit`).
"""

from __future__ import annotations

import importlib

from bifilar.jit import use_user_cache

use_user_cache()

# name -> the module that defines it
_EXPORTS = {
    "Rig": "bifilar.rig.file",
    "RigError": "bifilar.rig.file",
    "load_rig": "bifilar.rig.file",
    "rig_from_dict": "bifilar.rig.file",
    "rest_pose": "bifilar.rig.statics",
    "linearize": "bifilar.motion.modes",
    "Identified": "bifilar.identification.identify",
    "identify": "bifilar.identification.identify",
    "linear_period": "bifilar.identification.identify",
    "simulated_period": "bifilar.identification.identify",
    "read_record": "bifilar.identification.records.read",
    "fit_oscillation": "bifilar.identification.records.fit",
    "identify_records": "bifilar.identification.records.pipeline",
    "read_hangings": "bifilar.identification.hangings",
    "fit_hangings": "bifilar.identification.hangings",
}

__all__ = sorted(_EXPORTS)

TYPE_CHECKING = False  # typing's own would import typing (2 ms); type checkers know this spelling too
if TYPE_CHECKING:  # for type checkers and the import graph (tests/test_imports.py); at run time: __getattr__
    from bifilar.identification.hangings import fit_hangings, read_hangings
    from bifilar.identification.identify import Identified, identify, linear_period, simulated_period
    from bifilar.identification.records.fit import fit_oscillation
    from bifilar.identification.records.pipeline import identify_records
    from bifilar.identification.records.read import read_record
    from bifilar.motion.modes import linearize
    from bifilar.rig.file import Rig, RigError, load_rig, rig_from_dict
    from bifilar.rig.statics import rest_pose


def __getattr__(name: str):
    """An exported name, imported from its module at first use (and kept)."""
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_EXPORTS[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
