"""The air around the body: potential-flow added mass of an ellipsoid, and linear + quadratic drag.

The rig file's optional ``[air]`` table (docs/air.md) gives the fluid (``density`` kg/m^3,
``viscosity`` Pa s, dynamic) and the body's aerodynamic shape: an ellipsoid by its semi-axes
(``shape = "ellipsoid"``, ``size`` m) or a box by its edge lengths (``shape = "box"``, ``size`` m,
replaced by its inscribed ellipsoid, MuJoCo's convention for a box geom), centred at ``center`` (body
frame, m) with its axes turned by the rotation vector ``rotation`` (body frame, rad). Optional:
``drag = [blunt, slender, angular]`` (MuJoCo's coefficients, default its 0.5, 0.25, 1.5) and
``added_std`` (relative standard deviation of the added inertia, default 0). It is read with the rig file
(``Rig.air``) and used by the motion kernels, so it lives with the rig, below them.

Added mass (Lamb, Hydrodynamics 6th ed. 1932, §114-115 and §121; Tuckerman, NACA Report 210, 1925):
with semi-axes (a, b, c) and Lamb's coefficients alpha0 = a b c int_0^inf dl / ((a^2 + l) D),
D = sqrt((a^2 + l)(b^2 + l)(c^2 + l)) (and beta0, gamma0 cyclically), written with Carlson's
integral as alpha0 = 2/3 a b c R_D(b^2, c^2, a^2),

    m_x = rho V alpha0 / (2 - alpha0),
    I_x = rho V / 5 (b^2 - c^2)^2 (gamma0 - beta0) / (2 (b^2 - c^2) + (b^2 + c^2)(beta0 - gamma0)),

V = 4/3 pi a b c, cyclically for y and z. In the ellipsoid's own axes at its centre the 6x6 tensor is
diag(m_x, m_y, m_z, I_x, I_y, I_z) (three planes of symmetry); :func:`added_mass` moves it to the
body's COM and axes. The fluid's kinetic energy is 1/2 [v; w]^T M_A [v; w].

Drag (the stateless model of MuJoCo's ellipsoid fluid model, ``doc/computation/fluid.rst``, after
Andersen, Pesavento & Wang, J. Fluid Mech. 541, 2005; linear part Stokes 1850 for the sphere of mean
radius), on the ellipsoid's centre velocity v and angular velocity w in its axes:

    f = -rho [C_blunt A_v + C_slender (A_max - A_v)] |v| v - 6 pi mu r_D v,
    g = -rho |u| w - 8 pi mu r_D^3 w,   u_i = w_i (C_angular I_D,i + C_slender (I_max - I_D,i)),

A_v the area projected normal to v, A_max = pi r_max r_mid, I_D,i = 8 pi / 15 r_i max(r_j, r_k)^4,
I_max = max_i I_D,i, r_D the mean semi-axis. The coefficients are empirical (fits to falling cards);
a real body's should come from its measured decay (``identify`` fits the damping).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from scipy.spatial.transform import Rotation
from scipy.special import elliprd

from bifilar.rig.checks import RigError, no_unknown, non_negative, positive, required, vector3

SHAPES = ("ellipsoid", "box")
DRAG_DEFAULT = (0.5, 0.25, 1.5)  # MuJoCo's fluidcoef[0:3] defaults: blunt, slender, angular
_KEYS = {"density", "viscosity", "shape", "size", "center", "rotation", "drag", "added_std"}


@dataclass(frozen=True)
class Air:
    """The fluid and the body's aerodynamic ellipsoid (see the module docstring)."""

    density: float  # kg/m^3
    viscosity: float  # Pa s (dynamic)
    semi_axes: np.ndarray  # m, along the ellipsoid's axes
    center: np.ndarray  # m, body frame
    axes: np.ndarray  # 3x3, columns the ellipsoid's axes in body coordinates
    drag: np.ndarray  # blunt, slender, angular (-)
    added_std: float = 0.0  # relative standard deviation of the added inertia (model error)
    shape: str = "ellipsoid"  # as written in the file ("box" is held as its inscribed ellipsoid)


def air_from_dict(raw: dict, source: str) -> Air:
    """The checked ``[air]`` table; :class:`RigError` names the field on any problem."""
    no_unknown(raw, _KEYS, source, "air.")
    shape = required(raw, "shape", source, "air.")
    if shape not in SHAPES:
        raise RigError(source, "air.shape", f"must be one of {', '.join(SHAPES)}, got {shape!r}")
    size = vector3(required(raw, "size", source, "air."), source, "air.size")
    for i, s in enumerate(size):
        positive(float(s), source, f"air.size[{i}]")
    drag_raw = raw.get("drag", list(DRAG_DEFAULT))
    if not isinstance(drag_raw, list) or len(drag_raw) != 3:
        raise RigError(source, "air.drag", "must be a list of three numbers: blunt, slender, angular")
    drag = np.array([non_negative(v, source, f"air.drag[{i}]") for i, v in enumerate(drag_raw)])
    rotvec = vector3(raw.get("rotation", [0.0, 0.0, 0.0]), source, "air.rotation")
    return Air(
        density=positive(required(raw, "density", source, "air."), source, "air.density"),
        viscosity=non_negative(raw.get("viscosity", 0.0), source, "air.viscosity"),
        semi_axes=size if shape == "ellipsoid" else 0.5 * size,
        center=vector3(raw.get("center", [0.0, 0.0, 0.0]), source, "air.center"),
        axes=Rotation.from_rotvec(rotvec).as_matrix(),
        drag=drag,
        added_std=non_negative(raw.get("added_std", 0.0), source, "air.added_std"),
        shape=shape,
    )


def lamb_coefficients(semi_axes) -> np.ndarray:
    """Lamb's (alpha0, beta0, gamma0) of an ellipsoid (dimensionless; they sum to 2)."""
    a2 = np.asarray(semi_axes, dtype=float) ** 2
    abc = float(np.sqrt(a2.prod()))
    return np.array([2.0 / 3.0 * abc * elliprd(a2[(i + 1) % 3], a2[(i + 2) % 3], a2[i]) for i in range(3)])


def added_mass_principal(semi_axes, density: float) -> np.ndarray:
    """(m_x, m_y, m_z, I_x, I_y, I_z): the added masses (kg) and moments (kg m^2) along the axes."""
    r = np.asarray(semi_axes, dtype=float)
    k = lamb_coefficients(r)
    fluid = density * 4.0 / 3.0 * np.pi * r.prod()  # rho V
    out = np.empty(6)
    out[:3] = fluid * k / (2.0 - k)
    for i in range(3):
        j, l = (i + 1) % 3, (i + 2) % 3
        d = r[j] ** 2 - r[l] ** 2
        if d == 0.0:  # axisymmetric about axis i: turning about it displaces no fluid
            out[3 + i] = 0.0
            continue
        out[3 + i] = fluid / 5.0 * d**2 * (k[l] - k[j]) / (2.0 * d + (r[j] ** 2 + r[l] ** 2) * (k[j] - k[l]))
    return out


def transport(axes: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """T (6x6) with [v_e; w_e] = T [v; w]: the velocity of a point at ``offset`` from the reference
    point and the angular velocity, both in the frame whose axes are the columns of ``axes``."""
    cross = np.array([[0.0, -offset[2], offset[1]], [offset[2], 0.0, -offset[0]], [-offset[1], offset[0], 0.0]])
    t = np.zeros((6, 6))
    t[:3, :3] = axes.T
    t[:3, 3:] = -axes.T @ cross  # v + w x c = v - [c]x w
    t[3:, 3:] = axes.T
    return t


def added_mass(air: Air, com: np.ndarray) -> np.ndarray:
    """The 6x6 added-mass tensor about the body's COM ``com`` (body frame, m), in body axes, acting
    on [v_COM; omega] (kg, kg m, kg m^2)."""
    t = transport(air.axes, air.center - com)
    return t.T @ np.diag(added_mass_principal(air.semi_axes, air.density)) @ t


def added_inertia(air: Air, com: np.ndarray, axis: np.ndarray) -> float:
    """The added moment of inertia about the body axis ``axis`` (unit, body frame) through the COM."""
    e6 = np.concatenate([np.zeros(3), axis])
    return float(e6 @ added_mass(air, com) @ e6)


def fluid_momentum(air: Air, com: np.ndarray, rotation: np.ndarray, velocity, omega) -> np.ndarray:
    """The fluid's impulse [P; L] (world frame; L about the COM) of the body moving with COM
    ``velocity`` and ``omega`` (world frame) at ``rotation`` (body -> world)."""
    rot6 = np.kron(np.eye(2), rotation)
    return rot6 @ added_mass(air, com) @ rot6.T @ np.concatenate([velocity, omega])


def fluid_drag(air: Air, com: np.ndarray, rotation: np.ndarray, velocity, omega) -> tuple[np.ndarray, np.ndarray]:
    """The drag force (N) and torque about the COM (N m), world frame, on the body moving with COM
    ``velocity`` and ``omega`` (world) at ``rotation`` (body -> world); ``com`` in the body frame."""
    axes = rotation @ air.axes
    arm = rotation @ (air.center - com)
    velocity, omega = np.asarray(velocity, dtype=float), np.asarray(omega, dtype=float)
    f_e, g_e = drag_wrench(axes.T @ (velocity + np.cross(omega, arm)), axes.T @ omega, drag_parameters(air))
    force = axes @ f_e
    return force, axes @ g_e + np.cross(arm, force)


def drag_parameters(air: Air) -> np.ndarray:
    """(r_x, r_y, r_z, rho, mu, C_blunt, C_slender, C_angular) for :func:`drag_wrench`."""
    return np.concatenate([air.semi_axes, [air.density, air.viscosity], air.drag])


@njit(cache=True)
def drag_wrench(v, w, q):
    """Drag force (N) and torque (N m) on the ellipsoid, in its axes and about its centre, for its
    centre velocity ``v`` and angular velocity ``w`` (its axes); ``q`` from :func:`drag_parameters`."""
    r = q[0:3]
    rho, mu, c_blunt, c_slender, c_angular = q[3], q[4], q[5], q[6], q[7]
    r_max, r_min = r.max(), r.min()
    r_mid = r.sum() - r_max - r_min
    r_d = r.sum() / 3.0
    speed = np.sqrt(v @ v)
    force = -6.0 * np.pi * mu * r_d * v
    if speed > 0.0:
        u = v / speed
        num = (r[1] ** 4 * r[2] ** 4 * u[0] ** 2 + r[2] ** 4 * r[0] ** 4 * u[1] ** 2
               + r[0] ** 4 * r[1] ** 4 * u[2] ** 2)
        den = r[1] ** 2 * r[2] ** 2 * u[0] ** 2 + r[2] ** 2 * r[0] ** 2 * u[1] ** 2 + r[0] ** 2 * r[1] ** 2 * u[2] ** 2
        area = np.pi * np.sqrt(num / den)
        a_max = np.pi * r_max * r_mid
        force -= rho * (c_blunt * area + c_slender * (a_max - area)) * speed * v
    i_d = np.empty(3)
    for i in range(3):
        i_d[i] = 8.0 * np.pi / 15.0 * r[i] * max(r[(i + 1) % 3], r[(i + 2) % 3]) ** 4
    i_max = i_d.max()
    mom = w * (c_angular * i_d + c_slender * (i_max - i_d))
    torque = -rho * np.sqrt(mom @ mom) * w - 8.0 * np.pi * mu * r_d**3 * w
    return force, torque
