"""Identification: moments of inertia from measured periods, signals or tensions, with their
propagated uncertainty.

One function per measurement (``docs/identification.md``), here by name: a moment measured from a
period or records with its propagated sigma, as ``validate identify`` reports it (:func:`measure`,
returning a frozen :class:`Measurement`; a fixture subtracted: :func:`subtract_tare`), a period inverted
into the moment about a body axis (:func:`invert_period`; with the amplitude corrected for:
:func:`bifilar.identification.identify.identify`, also :func:`bifilar.identify`), the rig's own
periods (:func:`linear_period`, :func:`simulated_period`, :func:`amplitude_ratio`), a period from
crossing times (:func:`period`), records read, fitted and pooled (:func:`read_record`,
:func:`fit_oscillation`, :func:`law_for`, :func:`identify_records`, :func:`pool`), the tensor from
hangings (:func:`identify_tensor`, or from a file: :func:`read_hangings`, :func:`fit_hangings`), a
plan of hangings (:func:`candidates`; the choice itself: :func:`bifilar.identification.plan.plan`),
the parallel-axis transfer (:func:`parallel_axis`, :func:`parallel_axis_moment`, :func:`object_part`)
and the uncertainty (:func:`propagate_linear`, :func:`monte_carlo`). The modules ``identify`` and
``plan`` keep their names, so their functions of the same name are reached through them.

A minute of a swing of the bench plate filmed at 60 frames/s (here made up, with a 1.9 s period and
damped), its period fitted and inverted into the moment about z (run from the project's folder):

>>> import numpy as np
>>> from bifilar import load_rig
>>> from bifilar.identification import fit_oscillation, invert_period
>>> rig = load_rig("models/rigs/bench_plate.toml")
>>> t = np.arange(0.0, 60.0, 1.0 / 60.0)
>>> angle = 0.05 * np.exp(-t / 100.0) * np.cos(2.0 * np.pi * t / 1.9)
>>> fit = fit_oscillation(t, angle, "angle")
>>> print(f"{fit.period:.4f} s, {fit.cycles} cycles")
1.9000 s, 31 cycles
>>> found = invert_period(rig, "z", fit.period)
>>> print(f"{found.moment:.4f} kg m^2, d ln T / d ln J = {found.sensitivity:.2f}")
0.1346 kg m^2, d ln T / d ln J = 0.50

The same period through :func:`measure`: the moment with the sigma propagated from the rig file's
``[uncertainty]`` (the stopwatch's period sigma, the tape measure's lengths, the scale's mass):

>>> from bifilar.identification import measure
>>> result = measure(rig, "z", period=fit.period)
>>> print(f"{result.inertia:.4f} +- {result.std:.4f} kg m^2")
0.1346 +- 0.0005 kg m^2

The names load on first use (PEP 562): importing one module of the package does not import them all.
"""

from __future__ import annotations

import importlib

# name -> the module that defines it, and the name there where it differs
_EXPORTS = {
    "Identified": "bifilar.identification.identify",
    "invert_period": "bifilar.identification.identify",
    "linear_period": "bifilar.identification.identify",
    "simulated_period": "bifilar.identification.identify",
    "amplitude_ratio": "bifilar.identification.identify",
    "amplitude_coefficient": "bifilar.identification.identify",
    "Measurement": "bifilar.identification.measurement",
    "measure": "bifilar.identification.measurement",
    "subtract_tare": "bifilar.identification.measurement",
    "Period": "bifilar.identification.periods",
    "period": "bifilar.identification.periods",
    "Record": "bifilar.identification.records.read",
    "read_record": "bifilar.identification.records.read",
    "OscillationFit": "bifilar.identification.records.fit",
    "fit_oscillation": "bifilar.identification.records.fit",
    "AmplitudeLaw": "bifilar.identification.records.law",
    "RecordOptions": "bifilar.identification.records.pipeline",
    "Trial": "bifilar.identification.records.pipeline",
    "identify_records": "bifilar.identification.records.pipeline",
    "law_for": "bifilar.identification.records.pipeline",
    "pool": "bifilar.identification.records.pipeline",
    "Hanging": "bifilar.identification.tensor",
    "Tare": "bifilar.identification.tensor",
    "Tensor": "bifilar.identification.tensor",
    "identify_tensor": "bifilar.identification.tensor",
    "read_hangings": "bifilar.identification.hangings",
    "fit_hangings": "bifilar.identification.hangings",
    "candidates": "bifilar.identification.plan",
    "parallel_axis": "bifilar.identification.transfer",
    "parallel_axis_moment": "bifilar.identification.transfer",
    "object_part": "bifilar.identification.transfer",
    "propagate_linear": ("bifilar.identification.propagation", "linear"),
    "monte_carlo": "bifilar.identification.propagation",
}

__all__ = sorted(_EXPORTS)

TYPE_CHECKING = False  # typing's own would import typing (2 ms); type checkers know this spelling too
if TYPE_CHECKING:  # for type checkers and the import graph (tests/test_imports.py); at run time: __getattr__
    from bifilar.identification.hangings import fit_hangings, read_hangings
    from bifilar.identification.identify import (Identified, amplitude_coefficient, amplitude_ratio, invert_period,
                                                 linear_period, simulated_period)
    from bifilar.identification.measurement import Measurement, measure, subtract_tare
    from bifilar.identification.periods import Period, period
    from bifilar.identification.plan import candidates
    from bifilar.identification.propagation import linear as propagate_linear
    from bifilar.identification.propagation import monte_carlo
    from bifilar.identification.records.fit import OscillationFit, fit_oscillation
    from bifilar.identification.records.law import AmplitudeLaw
    from bifilar.identification.records.pipeline import RecordOptions, Trial, identify_records, law_for, pool
    from bifilar.identification.records.read import Record, read_record
    from bifilar.identification.tensor import Hanging, Tare, Tensor, identify_tensor
    from bifilar.identification.transfer import object_part, parallel_axis, parallel_axis_moment


def __getattr__(name: str):
    """An exported name, imported from its module at first use (and kept)."""
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    where = _EXPORTS[name]
    module, attribute = where if isinstance(where, tuple) else (where, name)
    value = getattr(importlib.import_module(module), attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
