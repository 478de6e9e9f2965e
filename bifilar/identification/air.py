"""The body's own moment of inertia from the apparent one a bifilar measures in air.

A swing in air moves air with it, so the moment identified from a period with a vacuum model is the
body's plus the air's added moment about the axis (docs/air.md):

    J_body = J_apparent - e6^T M_A e6,   e6 = (0, e),

M_A the added-mass tensor of the rig's ``[air]`` about the COM (:func:`bifilar.rig.air.added_inertia`).
This is exact for a mode that turns about a principal axis of the air's ellipsoid through the COM with
the COM at rest (a symmetric rig's yaw); where the mode also moves the COM, the added mass along that
motion shifts the period too and the subtraction is first order only. Standard deviation: the
apparent moment's and the added moment's (``[air].added_std`` of it) in quadrature.
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


def vacuum(rig: Rig) -> Rig:
    """The rig without its ``[air]``: the model whose inversion gives the apparent moment."""
    return replace(rig, air=None)


def without_air(rig: Rig, axis: np.ndarray, apparent: float, apparent_std: float) -> WithoutAir:
    """Subtract the air's added moment about the body axis ``axis`` (unit vector, body frame) from
    the ``apparent`` moment identified with the vacuum model."""
    if rig.air is None:
        return WithoutAir(apparent, apparent_std, 0.0, 0.0)
    air = added_inertia(rig.air, rig.com, np.asarray(axis, dtype=float))
    std = float(np.hypot(apparent_std, rig.air.added_std * air))
    return WithoutAir(apparent - air, std, air, air / apparent)
