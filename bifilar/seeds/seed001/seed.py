"""Seed 001's equations of motion as printed: constants A..E, A1, A2, the energies, the dissipation
function F = k1 E1k + k2 E2k, the explicit accelerations f and g, and the special case r_m2 = 0.

Each function transcribes one printed formula symbol for symbol, so that the validation can check the
seed term by term against MuJoCo; none of them is rearranged. The one printed formula that fails is
``g``: it divides by 2C - B cos(phi2), which vanishes at cos(phi2) = 2C/B whenever B > 2C (a weight
m2 nearer the outer axis than r1, as in ``params.toml``), although phi2'' is finite there.
:func:`g_fixed` takes phi2'' from the second Lagrange equation instead, whose coefficient 2C never
vanishes. Arguments are Python floats (the integrators call these millions of times); angles in
rad, rates in rad/s, accelerations in rad/s^2, energies in J.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import cos, sin

import numpy as np

from .params import Params


@dataclass(frozen=True)
class Constants:
    """The seed's lumped constants: A, B, C (kg m^2), D, E (N m), A1, A2 (kg m^2), k1, k2 (1/s)."""

    A: float
    B: float
    C: float
    D: float
    E: float
    A1: float
    A2: float
    k1: float
    k2: float

    @classmethod
    def from_params(cls, p: Params) -> Constants:
        I_M, I_m1, I_m2 = p.M * p.r1**2, p.m1 * p.r_m1**2, p.m2 * p.r_m2**2
        A1 = (p.I_arm1 + I_M + I_m1) / 2.0
        A2 = (p.I_arm2 + I_m2 + p.m2 * p.r1**2 + p.m_arm2 * p.r1**2) / 2.0
        return cls(
            A=(p.I_arm1 + I_M + I_m1 + p.I_arm2 + I_m2 + p.m2 * p.r1**2 + p.m_arm2 * p.r1**2) / 2.0,
            B=p.m2 * p.r1 * p.r_m2,
            C=(p.I_arm2 + I_m2) / 2.0,
            D=(p.M * p.r1 + p.m1 * p.r_m1 - p.m_arm2 * p.r1 - p.m2 * p.r1) * p.g,
            E=p.m2 * p.r_m2 * p.g,
            A1=A1,
            A2=A2,
            k1=p.k1,
            k2=p.k2,
        )


def kinetic(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """E_k = (A - B cos phi2) phi1'^2 + C phi2'^2 + (2C - B cos phi2) phi1' phi2'."""
    return (c.A - c.B * cos(p2)) * w1**2 + c.C * w2**2 + (2 * c.C - c.B * cos(p2)) * w1 * w2


def potential(c: Constants, p1: float, p2: float) -> float:
    """E_p = D sin phi1 + E sin(phi1 + phi2), zero with both arms horizontal."""
    return c.D * sin(p1) + c.E * sin(p1 + p2)


def dissipation(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """The printed F = k1 A1 phi1'^2 + k2 A2 phi1'^2 - k2 B phi1'^2 cos phi2 + k2 C phi2'^2
    + k2 (2C - B cos phi2) phi1' phi2' (W); the energy decreases at 2F."""
    c2 = cos(p2)
    return (c.k1 * c.A1 + c.k2 * c.A2 - c.k2 * c.B * c2) * w1**2 + c.k2 * c.C * w2**2 + c.k2 * (2 * c.C - c.B * c2) * w1 * w2


def mass_matrix(c: Constants, p2: float) -> np.ndarray:
    """The coefficients of (phi1'', phi2'') in the printed d/dt(dL/dphi_i') (kg m^2)."""
    m12 = 2 * c.C - c.B * cos(p2)
    return np.array([[2 * (c.A - c.B * cos(p2)), m12], [m12, 2 * c.C]])


def bias(c: Constants, p1: float, p2: float, w1: float, w2: float) -> np.ndarray:
    """d/dt(dL/dphi_i') without its phi'' terms, minus dL/dphi_i, as printed (N m): MuJoCo's
    ``qfrc_bias`` (Coriolis, centripetal and gravity)."""
    s2, c12 = sin(p2), cos(p1 + p2)
    dLdp1 = -c.D * cos(p1) - c.E * c12
    dLdp2 = c.B * w1**2 * s2 + c.B * w1 * w2 * s2 - c.E * c12
    return np.array([2 * c.B * w1 * w2 * s2 + c.B * w2**2 * s2 - dLdp1, c.B * w1 * w2 * s2 - dLdp2])


def friction_gradient(c: Constants, p1: float, p2: float, w1: float, w2: float) -> np.ndarray:
    """(dF/dphi1', dF/dphi2') as printed (N m); the friction torques are its negative."""
    m12 = c.k2 * (2 * c.C - c.B * cos(p2))
    return np.array([2 * (c.k1 * c.A1 + c.k2 * c.A2 - c.k2 * c.B * cos(p2)) * w1 + m12 * w2, 2 * c.k2 * c.C * w2 + m12 * w1])


def f(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """The printed phi1'' (rad/s^2)."""
    c2, s2 = cos(p2), sin(p2)
    num = (
        2 * c.C * c.D * cos(p1)
        + (4 * c.C * (c.k1 * c.A1 + c.k2 * c.A2) - c.k2 * (4 * c.C**2 + c.B**2 * c2**2)) * w1
        + c.B * c.E * c2 * cos(p1 + p2)
        + 4 * c.B * c.C * w1 * w2 * s2
        + (2 * c.B * c.C - c.B**2 * c2) * w1**2 * s2
        + 2 * c.B * c.C * w2**2 * s2
    )
    return num / ((2 * c.C - c.B * c2) ** 2 - 4 * c.C * (c.A - c.B * c2))


def g(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """The printed phi2'' (rad/s^2), from the first Lagrange equation: singular where
    2C = B cos(phi2)."""
    c2, s2 = cos(p2), sin(p2)
    num = (
        2 * (c.B * c2 - c.A) * f(c, p1, p2, w1, w2)
        - 2 * c.B * w1 * w2 * s2
        - c.B * w2**2 * s2
        - c.D * cos(p1)
        - c.E * cos(p1 + p2)
        + 2 * (c.k2 * c.B * c2 - c.k1 * c.A1 - c.k2 * c.A2) * w1
        - c.k2 * (2 * c.C - c.B * c2) * w2
    )
    return num / (2 * c.C - c.B * c2)


def g_fixed(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """phi2'' from the seed's second Lagrange equation, (2C - B cos phi2) f + 2C phi2'' = B phi1'^2
    sin phi2 - E cos(phi1 + phi2) - 2 k2 C phi2' - k2 (2C - B cos phi2) phi1': regular wherever the
    system is (C > 0)."""
    m12 = 2 * c.C - c.B * cos(p2)
    rhs = c.B * w1**2 * sin(p2) - c.E * cos(p1 + p2) - 2 * c.k2 * c.C * w2 - c.k2 * m12 * w1
    return (rhs - m12 * f(c, p1, p2, w1, w2)) / (2 * c.C)


def special_f(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """The printed phi1'' of the balanced outer arm (r_m2 = 0, so B = E = 0)."""
    return ((c.k1 * c.A1 + c.k2 * c.A2 - c.k2 * c.C) * w1 + 0.5 * c.D * cos(p1)) / (c.C - c.A)


def special_g(c: Constants, p1: float, p2: float, w1: float, w2: float) -> float:
    """The printed phi2'' of the balanced outer arm (r_m2 = 0)."""
    return (c.A1 * (c.k2 - c.k1) * w1 + c.k2 * (c.A - c.C) * w2 - 0.5 * c.D * cos(p1)) / (c.C - c.A)
