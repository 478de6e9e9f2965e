"""The axes a sweep file may vary, each a function (rig, value) -> rig, applied exactly as documented.

World frame z up. "Span" axes move the two points of a pair symmetrically about their midpoint along
the line that joins them (the pair: the two anchors, or the two attachments, of wires 1 and 2), so the
midpoint and the direction are the base rig's; "height" axes move along world z (anchors) or body z
(attachments). The span and height axes act on wires 1 and 2, the pair that defines a bifilar rig;
``wire_length`` and ``platform_radius`` act on every wire (a trifilar platform's axes).

- ``wire_length``: every wire's length (m).
- ``wire_length_2``: wire 2's length alone (m), for unequal wires; applied after ``wire_length``.
- ``anchor_span``: the distance between the two ceiling anchors (m).
- ``attach_span``: the distance between the two attachments (m), in the body frame.
- ``attach_inset``: both attachments moved this far (m) towards each other along the line that joins
  them, from the base rig's positions: the span becomes the base's minus twice the inset. With a
  suspension file's base (the boat's attachments at the deck's ends) it is the thesis's distance from
  the deck's ends (Table 8.2.1). A file gives ``attach_span`` or ``attach_inset``, not both.
- ``attach_height``: both attachments' body-frame z (m).
- ``anchor_height_difference``: anchor 2's world z minus anchor 1's (m), about their mean height.
- ``platform_radius``: every attachment at this horizontal distance (m) from the body-frame vertical
  through the attachments' centroid, and every anchor at it from the world vertical through the
  anchors' centroid, each along its own direction (vertical wires stay vertical).
- ``axial_stiffness``: every wire's E A (N): the wires become elastic, ``length`` their unstretched
  length (docs/elastic-wires.md).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from bifilar.rig import Rig


def _wires(rig: Rig, **changes) -> Rig:
    wires = list(rig.wires)
    for index, fields in changes.items():
        i = int(index[1:])
        wires[i] = replace(wires[i], **fields)
    return replace(rig, wires=tuple(wires))


def _span(a: np.ndarray, b: np.ndarray, span: float) -> tuple[np.ndarray, np.ndarray]:
    """The pair moved symmetrically about its midpoint to distance ``span``."""
    mid, half = 0.5 * (a + b), 0.5 * (b - a)
    direction = half / np.linalg.norm(half)
    return mid - 0.5 * span * direction, mid + 0.5 * span * direction


def wire_length(rig: Rig, value: float) -> Rig:
    return replace(rig, wires=tuple(replace(w, length=value) for w in rig.wires))


def wire_length_2(rig: Rig, value: float) -> Rig:
    return _wires(rig, w1={"length": value})


def anchor_span(rig: Rig, value: float) -> Rig:
    a, b = _span(rig.wires[0].anchor, rig.wires[1].anchor, value)
    return _wires(rig, w0={"anchor": a}, w1={"anchor": b})


def attach_span(rig: Rig, value: float) -> Rig:
    a, b = _span(rig.wires[0].attach, rig.wires[1].attach, value)
    return _wires(rig, w0={"attach": a}, w1={"attach": b})


def attach_inset(rig: Rig, value: float) -> Rig:
    return attach_span(rig, attach_span_of(rig) - 2.0 * value)


def attach_span_of(rig: Rig) -> float:
    """Distance (m) between the attachments of wires 1 and 2, in the body frame."""
    return float(np.linalg.norm(rig.wires[1].attach - rig.wires[0].attach))


def attach_height(rig: Rig, value: float) -> Rig:
    a, b = rig.wires[0].attach.copy(), rig.wires[1].attach.copy()
    a[2] = b[2] = value
    return _wires(rig, w0={"attach": a}, w1={"attach": b})


def anchor_height_difference(rig: Rig, value: float) -> Rig:
    a, b = rig.wires[0].anchor.copy(), rig.wires[1].anchor.copy()
    mean = 0.5 * (a[2] + b[2])
    a[2], b[2] = mean - 0.5 * value, mean + 0.5 * value
    return _wires(rig, w0={"anchor": a}, w1={"anchor": b})


def _radial(points: np.ndarray, radius: float) -> np.ndarray:
    centre = points.mean(axis=0)
    arm = points - centre
    arm[:, 2] = 0.0
    norm = np.linalg.norm(arm, axis=1)
    if norm.min() <= 0.0:
        raise ValueError("a point on the platform's axis has no radial direction")
    return centre + np.column_stack([arm[:, :2] * (radius / norm)[:, None], points[:, 2] - centre[2]])


def platform_radius(rig: Rig, value: float) -> Rig:
    attach = _radial(np.array([w.attach for w in rig.wires]), value)
    anchor = _radial(np.array([w.anchor for w in rig.wires]), value)
    return replace(rig, wires=tuple(replace(w, attach=a, anchor=b) for w, a, b in zip(rig.wires, attach, anchor)))


def axial_stiffness(rig: Rig, value: float) -> Rig:
    return replace(rig, wires=tuple(replace(w, axial_stiffness=value) for w in rig.wires))


# Application order: lengths first so that wire_length_2 overrides wire 2's share of wire_length.
AXES = {
    "wire_length": wire_length,
    "wire_length_2": wire_length_2,
    "anchor_span": anchor_span,
    "attach_span": attach_span,
    "attach_inset": attach_inset,
    "attach_height": attach_height,
    "anchor_height_difference": anchor_height_difference,
    "platform_radius": platform_radius,
    "axial_stiffness": axial_stiffness,
}
# Axes whose values must be above zero -> what a value is, for the message that refuses one.
POSITIVE = {**dict.fromkeys(("wire_length", "wire_length_2", "anchor_span", "attach_span", "platform_radius"),
                            "a distance, m"),
            "axial_stiffness": "a wire's E A, N"}


def configure(rig: Rig, values: dict[str, float]) -> Rig:
    """The base rig with every axis in ``values`` applied, in :data:`AXES` order."""
    for name, apply in AXES.items():
        if name in values:
            rig = apply(rig, float(values[name]))
    return rig


