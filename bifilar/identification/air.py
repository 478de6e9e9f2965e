"""The body's own moment of inertia and the apparent one a bifilar measures in air.

A swing in air moves air with it: the period is the body's moment plus the air's added inertia's
(docs/air.md). :func:`measure <bifilar.identification.measurement.measure>` inverts the period with
the rig in still air (:func:`still`: the added mass kept, the drag left out, its damping being the
record's to fit), whose mass matrix is the body's plus the air's 6x6 added mass M_A about the COM: the
moment found is the body's own, for any mode (the COM's motion included). The apparent moment, the
one a vacuum model would call it, is reported beside it as

    J_apparent = J_body + e6^T M_A e6,   e6 = (0, e),

which is what a vacuum inversion gives exactly for a mode turning about a principal axis of the air's
ellipsoid through the COM with the COM at rest (a symmetric rig's yaw), and to first order elsewhere.
Standard deviation of the body's moment: the propagated one and the added moment's (``[air].added_std``
of it) in quadrature.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from bifilar.rig.air import added_inertia
from bifilar.rig import Rig


@dataclass(frozen=True)
class WithoutAir:
    """The body's own moment (kg m^2) with its standard deviation, the air's added moment and its
    share of the apparent (measured) moment."""

    inertia: float
    std: float
    air_inertia: float
    air_share: float


def still(rig: Rig) -> Rig:
    """The rig in still air: the ``[air]``'s added mass kept, its drag (and viscosity) zero. The drag's
    damping shifts a period by a relative ~zeta^2 / 2 and is fitted from records, not modelled."""
    if rig.air is None:
        return rig
    return replace(rig, air=replace(rig.air, viscosity=0.0, drag=np.zeros(3)))


def vacuum(rig: Rig) -> Rig:
    """The rig without its ``[air]``: the model whose inversion gives the apparent moment."""
    return replace(rig, air=None)


def added_moment(rig: Rig, axis: np.ndarray) -> float:
    """The air's added moment e6^T M_A e6 (kg m^2) about the body axis ``axis`` (unit vector, body
    frame) through the COM; 0 in a vacuum."""
    return 0.0 if rig.air is None else added_inertia(rig.air, rig.com, np.asarray(axis, dtype=float))


def with_air(rig: Rig, axis: np.ndarray, own: float, own_std: float) -> WithoutAir:
    """The body's ``own`` moment (identified in still air) about the body axis ``axis`` (unit vector,
    body frame) with its sigma widened by the added moment's, the air's added moment and its share of
    the apparent moment ``own`` + added."""
    if rig.air is None:
        return WithoutAir(own, own_std, 0.0, 0.0)
    air = added_moment(rig, axis)
    std = float(np.hypot(own_std, rig.air.added_std * air))
    return WithoutAir(own, std, air, air / (own + air))
