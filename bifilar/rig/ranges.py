"""Physical ranges of every rig-file field: what a real rig can be and the numerics can hold.

A rig file that parses can still describe something no bifilar pendulum is (a 1e-30 kg body, 1e200 m
coordinates, two attachments 10 nm apart, a spin of 1e15 rad/s): the physics would then fail deep in
a matrix factorisation or an integrator, or run for ever. These checks refuse such a file up front,
in one line naming the field, with the range and its reason. Absolute ranges bound each quantity by
what a bench can hold; the scale-aware ones compare it with the rig's own size

    S = the longest of the wire lengths, the anchor span and the attachment span (m),

so that a 5 cm model and a 50 m hall are judged alike. The table :data:`RANGES` is what
``docs/rig-file.md`` documents; :func:`check_ranges` applies it to a parsed rig.
"""

from __future__ import annotations

import numpy as np

from bifilar.rig.checks import RigError, within

# field -> (low, high, unit, reason). Absolute ranges.
RANGES = {
    "gravity": (0.1, 100.0, "m/s^2", "from a small moon to ten times the Earth's"),
    "body.mass": (1e-3, 1e6, "kg", "from a gram to a thousand tonnes"),
    "wire[i].length": (1e-3, 1e3, "m", "from a millimetre to a kilometre"),
    "wire[i].axial_stiffness": (1.0, 1e10, "N", "E A: from a thin rubber cord to a 10 cm steel bar"),
    "wire[i].linear_density": (0.0, 10.0, "kg/m", "positive, up to a 4 cm steel rope's; heavy wires: docs/heavy-wires.md"),
    "coordinates": (-1e4, 1e4, "m", "every component of anchor, attach and com"),
    "torsion.stiffness": (1e-6, 1e5, "N m/rad", "from a silk fibre to a 5 cm steel bar a metre long"),
    "air.density": (1e-3, 2e3, "kg/m^3", "from thin air to twice water's"),
    "air.viscosity": (0.0, 10.0, "Pa s", "0 (inviscid) to ten thousand times water's"),
    "air.drag": (0.0, 100.0, "", "MuJoCo's coefficients are O(1)"),
    "air.added_std": (0.0, 1.0, "", "a relative standard deviation: 0 .. 100 %"),
}
# The air's ellipsoid: each semi-axis between these fractions of the rig's size, its centre at most
# MAX_COM_OFFSET x the size from the COM (it is the body's own outline).
AIR_SIZE = (1e-4, 10.0)
MAX_WIRE_MASS = 0.5  # x body.mass: one wire's mass; heavier, the first-order heavy-wire model is not a model
MAX_WIRES = 64  # a rig is a body on a few wires; a 100,000-wire file is a mistake (it crashed MuJoCo)
MIN_ATTACH_SPAN = 1e-3  # x S: closer attachments hang the body from one point (a 1e-8 m pair is singular)
MAX_COM_OFFSET = 10.0  # x S: the COM's distance from the nearest attachment
MIN_INERTIA = 1e-9  # x m S^2: the smallest principal moment; below it the rotation is numerically rigid
MAX_INERTIA = 1e3  # x m S^2: the largest; a body 30 rig sizes across on a rig of size S is not hung by it
MAX_ROTATION = np.pi  # rad: |initial.rotation|; every orientation has a rotation vector of norm <= pi
MAX_OMEGA = 100.0  # x sqrt(g / l_min): |initial.omega|, a hundred times the pendulum's own rate
MAX_RELATIVE_SIGMA = 0.5  # uncertainty.* against its quantity: larger is not a measurement
MIN_RELATIVE_SIGMA = 1e-12  # a positive sigma below this of its quantity is rounding noise (or a denormal)
MAX_PERIOD_SIGMA = 100.0  # s


def rig_size(wires) -> float:
    """S (m): the longest of the wire lengths, the anchor span and the attachment span."""
    anchors = np.array([w.anchor for w in wires])
    attach = np.array([w.attach for w in wires])
    return float(max(max(w.length for w in wires), np.linalg.norm(anchors[0] - anchors[-1]),
                     np.linalg.norm(attach[0] - attach[-1])))


def check_ranges(rig, free_moment: int | None = None) -> None:
    """Raise :class:`RigError` for the first field of ``rig`` (a :class:`bifilar.rig.Rig`) outside its
    range; the order is the file's (gravity, body, wires, initial, uncertainty). ``free_moment``: the
    diagonal inertia entry being identified (its value is unknown or a guess): only the others are
    held to the inertia range."""
    src = rig.source
    low, high, unit, why = RANGES["gravity"]
    within(rig.gravity, low, high, src, "gravity", unit, why)
    low, high, unit, why = RANGES["body.mass"]
    within(rig.mass, low, high, src, "body.mass", unit, why)
    low, high, unit, why = RANGES["coordinates"]
    for k, x in enumerate(rig.com):
        within(float(x), low, high, src, f"body.com[{k}]", unit, why)
    for i, w in enumerate(rig.wires, start=1):
        for name, vec in (("anchor", w.anchor), ("attach", w.attach)):
            for k, x in enumerate(vec):
                within(float(x), low, high, src, f"wire[{i}].{name}[{k}]", unit, why)
        lo, hi, u, reason = RANGES["wire[i].length"]
        within(w.length, lo, hi, src, f"wire[{i}].length", u, reason)
        if w.axial_stiffness is not None:
            lo, hi, u, reason = RANGES["wire[i].axial_stiffness"]
            within(w.axial_stiffness, lo, hi, src, f"wire[{i}].axial_stiffness", u, reason)
        if w.linear_density:
            lo, hi, u, reason = RANGES["wire[i].linear_density"]
            within(w.linear_density, lo, hi, src, f"wire[{i}].linear_density", u, reason)
            within(w.linear_density * w.length, 0.0, MAX_WIRE_MASS * rig.mass, src, f"wire[{i}].linear_density", "kg",
                   f"the wire's mass, at most {MAX_WIRE_MASS:g} x the body's {rig.mass:.6g} kg: the heavy-wire model "
                   "is first order in that ratio")

    size = rig_size(rig.wires)
    span = float(np.linalg.norm(rig.wires[0].attach - rig.wires[1].attach))
    if span < MIN_ATTACH_SPAN * size:
        raise RigError(src, "wire[2].attach", f"coincides with wire[1].attach ({span:.3g} m apart, less than "
                       f"{MIN_ATTACH_SPAN:g} of the rig's size {size:.3g} m): the body would hang from one point")
    offset = min(float(np.linalg.norm(rig.com - w.attach)) for w in rig.wires)
    within(offset, 0.0, MAX_COM_OFFSET * size, src, "body.com", "m",
           f"its distance from the nearest attachment, at most {MAX_COM_OFFSET:g} x the rig's size {size:.3g} m")
    known = [i for i in range(3) if i != free_moment]
    moments = np.linalg.eigvalsh(rig.inertia[np.ix_(known, known)])
    scale = rig.mass * size**2
    if moments[0] < MIN_INERTIA * scale or moments[-1] > MAX_INERTIA * scale:
        raise RigError(src, "body.inertia", f"principal moments {_fmt(moments)} kg m^2 outside {MIN_INERTIA:g} .. "
                       f"{MAX_INERTIA:g} x mass x size^2 = {MIN_INERTIA * scale:.3g} .. {MAX_INERTIA * scale:.3g} kg m^2")

    within(float(np.linalg.norm(rig.initial_rotation)), 0.0, MAX_ROTATION, src, "initial.rotation", "rad",
           "the rotation vector's norm; every orientation has one of norm <= pi")
    rate = np.sqrt(rig.gravity / min(w.length for w in rig.wires))
    within(float(np.linalg.norm(rig.initial_omega)), 0.0, MAX_OMEGA * rate, src, "initial.omega", "rad/s",
           f"|omega| at most {MAX_OMEGA:g} x sqrt(g / shortest wire) = {MAX_OMEGA * rate:.3g} rad/s")
    _check_sigmas(rig, size)
    if rig.air is not None:
        _check_air(rig, size)


def _check_air(rig, size: float) -> None:
    air, src = rig.air, rig.source
    for name, value in (("density", air.density), ("viscosity", air.viscosity), ("added_std", air.added_std)):
        low, high, unit, why = RANGES[f"air.{name}"]
        within(float(value), low, high, src, f"air.{name}", unit, why)
    low, high, unit, why = RANGES["air.drag"]
    for k, c in enumerate(air.drag):
        within(float(c), low, high, src, f"air.drag[{k}]", unit, why)
    full = 1.0 if air.shape == "ellipsoid" else 2.0  # a box is written by its full edges
    for k, r in enumerate(air.semi_axes):
        within(float(r) * full, AIR_SIZE[0] * size, AIR_SIZE[1] * size, src, f"air.size[{k}]", "m",
               f"{AIR_SIZE[0]:g} .. {AIR_SIZE[1]:g} x the rig's size {size:.3g} m")
    within(float(np.linalg.norm(air.center - rig.com)), 0.0, MAX_COM_OFFSET * size, src, "air.center", "m",
           f"its distance from the COM, at most {MAX_COM_OFFSET:g} x the rig's size {size:.3g} m")


def _check_sigmas(rig, size: float) -> None:
    unc = rig.uncertainty
    scales = {
        "length": (min(w.length for w in rig.wires), "m"),
        "anchor": (size, "m"),
        "attach": (size, "m"),
        "com": (size, "m"),
        "mass": (rig.mass, "kg"),
    }
    for name, (scale, unit) in scales.items():
        sigma = getattr(unc, name)
        if sigma:
            within(sigma, MIN_RELATIVE_SIGMA * scale, MAX_RELATIVE_SIGMA * scale, rig.source, f"uncertainty.{name}",
                   unit, f"0 or {MIN_RELATIVE_SIGMA:g} .. {MAX_RELATIVE_SIGMA:g} of the quantity, {scale:.6g} {unit}")
    if unc.period:
        within(unc.period, 1e-12, MAX_PERIOD_SIGMA, rig.source, "uncertainty.period", "s", "0 or 1e-12 .. 100 s")


def _fmt(values) -> str:
    return "[" + ", ".join(f"{v:.3g}" for v in values) + "]"
