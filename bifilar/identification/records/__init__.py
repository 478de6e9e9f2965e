"""Measured records of a swinging rig, from file to moment of inertia.

The loop is :func:`.pipeline.identify_records`: read (:mod:`.read`) -> fit cycle by cycle
(:mod:`.fit`, its steps each a module: the cycles :mod:`.cycles`, what is left out :mod:`.clean`, the
phases' law :mod:`.phase_law`, the damping :mod:`.damping`, the spread :mod:`.spread`, a second mode
:mod:`.second_mode`, the whole record :mod:`.whole`) -> the amplitude law (:mod:`.law`) -> refit -> invert
-> pool. :mod:`.synthetic` makes records with real traits and a known truth.
"""

from .fit import OscillationFit, fit_oscillation
from .law import EXCESS_PRIOR, AmplitudeLaw
from .pipeline import RecordOptions, Trial, identify_records, law_for, pool
from .read import Record, read_record, unfold

__all__ = ["EXCESS_PRIOR", "AmplitudeLaw", "OscillationFit", "Record", "RecordOptions", "Trial", "fit_oscillation",
           "identify_records", "law_for", "pool", "read_record", "unfold"]
