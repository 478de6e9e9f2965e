"""The Solar Boat hung in a hall (thesis ch. 8.2): its rigs, the lowest point of its parts, and the
loads its deck carries.

A suspension file (TOML, ``models/solar_boat/suspension.toml``) names the parts file and the part
whose ends the attachments are counted from (``deck``), the hall (``hooks``: the two ceiling hooks,
world frame, m; ``wire_length``, m; ``hook_height``: hooks above the floor, m), the configurations
(``[[configuration]]``: ``name`` and ``inset``, m from the deck's ends) and the measurement errors
(``[uncertainty]``, as in a rig file). Every configuration uses the same hooks and wires, as the
thesis assumes.

Frames: world z up, gravity along -z; the body frame is the parts file's (for the boat: origin at the
centre of the top of the deck, x forward, y to port, z up). Wire 1 runs from the first hook to the
attachment at the deck's +x end (the bow), wire 2 from the second hook to the -x end, so the first
hook should be on the bow's side. Attachments are on the deck's centreline on its top face:
``deck.position + deck.rotation @ (+-(length/2 - inset), 0, height/2)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from bifilar.rig.checks import (
    RigError,
    no_unknown,
    non_negative,
    positive,
    read_toml,
    required,
    table,
    vector3,
)
from bifilar.bodies.composite import MassProperties, Part, load_parts, mass_properties, rig_body
from bifilar.rig import Rig, rig_from_dict

_TOP_KEYS = {"parts", "deck", "hall", "configuration", "uncertainty"}
_HALL_KEYS = {"hooks", "wire_length", "hook_height"}
_CONFIGURATION_KEYS = {"name", "inset"}


@dataclass(frozen=True)
class Configuration:
    """Attachments ``inset`` (m) in from both ends of the deck."""

    name: str
    inset: float


@dataclass(frozen=True)
class Suspension:
    """A parts file hung from a hall's two hooks in several configurations (module docstring)."""

    parts: tuple[Part, ...]
    deck: Part
    hooks: np.ndarray  # (2, 3), world, m
    wire_length: float  # m
    hook_height: float  # m, hooks above the floor
    configurations: tuple[Configuration, ...]
    uncertainty: dict  # the [uncertainty] table, as in a rig file
    source: str

    @property
    def properties(self) -> MassProperties:
        return mass_properties(list(self.parts))

    def configuration(self, name: str) -> Configuration:
        for c in self.configurations:
            if c.name == name:
                return c
        raise RigError(self.source, "configuration", f"no configuration named {name!r}")

    def attachments(self, config: Configuration) -> np.ndarray:
        """Body-frame attachment points (2, 3) of wires 1 and 2 (m)."""
        d = self.deck.dims
        ends = np.array([[s * (0.5 * d["length"] - config.inset), 0.0, 0.5 * d["height"]] for s in (1.0, -1.0)])
        return self.deck.position + ends @ self.deck.rotation.T

    @property
    def floor(self) -> float:
        """World z (m) of the hall's floor: ``hook_height`` under the highest hook."""
        return float(self.hooks[:, 2].max()) - self.hook_height

    def base_rig(self) -> Rig:
        """The boat with its attachments at the deck's ends (inset 0): the base rig of a boat sweep, from
        which the sweep's ``attach_inset`` counts the thesis's insets (bifilar/sweep/space.py)."""
        return self.rig(Configuration("ends", 0.0))

    def rig(self, config: Configuration) -> Rig:
        """The checked rig of one configuration, with the file's measurement errors."""
        attach = self.attachments(config)
        data = {
            "name": f"solar_boat_{config.name}",
            "body": rig_body(self.properties),
            "wire": [{"anchor": hook.tolist(), "attach": a.tolist(), "length": self.wire_length}
                     for hook, a in zip(self.hooks, attach)],
            "uncertainty": self.uncertainty,
        }
        return rig_from_dict(data, source=self.source)


def load_suspension(path: str | Path) -> Suspension:
    """Read and check a suspension file and its parts file; raise :class:`RigError` on any problem."""
    src = str(path)
    data = read_toml(path)
    no_unknown(data, _TOP_KEYS, src, "")
    parts_name = required(data, "parts", src, "")
    if not isinstance(parts_name, str) or not parts_name:
        raise RigError(src, "parts", "must be the parts file's path, relative to this file")
    parts = tuple(load_parts(Path(path).parent / parts_name))
    deck_name = required(data, "deck", src, "")
    deck = next((p for p in parts if p.name == deck_name), None)
    if deck is None:
        raise RigError(src, "deck", f"no part named {deck_name!r} in {parts_name}")
    if "width" not in deck.dims:
        raise RigError(src, "deck", f"part {deck_name!r} is a {deck.shape}; it must be a box, plate or beam")

    hall = table(data, "hall", src, mandatory=True)
    no_unknown(hall, _HALL_KEYS, src, "hall.")
    hooks_raw = required(hall, "hooks", src, "hall.")
    if not isinstance(hooks_raw, list) or len(hooks_raw) != 2:
        raise RigError(src, "hall.hooks", "must be two hooks, [[x, y, z], [x, y, z]] (m, world frame)")
    hooks = np.array([vector3(h, src, f"hall.hooks[{i}]") for i, h in enumerate(hooks_raw)])
    wire_length = positive(required(hall, "wire_length", src, "hall."), src, "hall.wire_length")
    hook_height = positive(required(hall, "hook_height", src, "hall."), src, "hall.hook_height")

    raw = data.get("configuration")
    if not isinstance(raw, list) or not raw or not all(isinstance(c, dict) for c in raw):
        raise RigError(src, "configuration", "missing: give the configurations as [[configuration]] tables")
    configurations = []
    half = 0.5 * deck.dims["length"]
    for i, c in enumerate(raw, start=1):
        prefix = f"configuration[{i}]."
        no_unknown(c, _CONFIGURATION_KEYS, src, prefix)
        name = required(c, "name", src, prefix)
        if not isinstance(name, str) or not name or name in (k.name for k in configurations):
            raise RigError(src, prefix + "name", f"must be a non-empty, unique string, got {name!r}")
        inset = non_negative(required(c, "inset", src, prefix), src, prefix + "inset")
        if inset >= half:
            raise RigError(src, prefix + "inset", f"{inset:g} m: must be less than half the deck length ({half:g} m)")
        configurations.append(Configuration(name, inset))

    unc = table(data, "uncertainty", src, mandatory=False)
    s = Suspension(parts, deck, hooks, wire_length, hook_height, tuple(configurations), unc, src)
    for c in s.configurations:
        s.rig(c)  # every configuration must hang: rig_from_dict checks the file and the reach
    return s


def lowest_point(parts, origin: np.ndarray, rotation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """World height (m) of the lowest point of the parts, and the index of the part that has it, for
    poses given by the body-frame origin (n, 3; world, m) and body->world rotation (n, 3, 3).

    Exact for each primitive: a box's centre minus its half edges projected on the vertical, a
    cylinder's centre minus half its length times |a_z| and its radius times sqrt(1 - a_z^2) (a: its
    axis), a sphere's centre minus its radius. Hollow shapes reach as low as their outer surface.
    """
    origin, rotation = np.atleast_2d(origin), np.reshape(rotation, (-1, 3, 3))
    heights = np.empty((len(parts), len(origin)))
    for k, p in enumerate(parts):
        centre_z = origin[:, 2] + rotation[:, 2, :] @ p.position
        up = rotation[:, 2, :] @ p.rotation  # world z components of the part's axes
        d = p.dims
        if "width" in d:
            half = 0.5 * np.array([d["length"], d["width"], d["height"]])
            heights[k] = centre_z - np.abs(up) @ half
        elif "length" in d:
            az = np.abs(up[:, 2])
            heights[k] = centre_z - 0.5 * d["length"] * az - d["radius"] * np.sqrt(np.clip(1.0 - az * az, 0.0, None))
        else:
            heights[k] = centre_z - d["radius"]
    index = np.argmin(heights, axis=0)
    return heights[index, np.arange(len(origin))], index


def attachment_forces(rig: Rig, com: np.ndarray, rotation: np.ndarray, tensions: np.ndarray) -> np.ndarray:
    """Force of each wire on the body at its attachment, in the body frame (n, wires, 3; N), for poses
    (COM, world, m; body->world rotation) and wire tensions (n, wires; N): the tension along the
    wire from the attachment towards its hook."""
    com, rotation = np.atleast_2d(com), np.reshape(rotation, (-1, 3, 3))
    tensions = np.atleast_2d(tensions)
    out = np.empty((len(com), len(rig.wires), 3))
    for i, w in enumerate(rig.wires):
        point = com + rotation @ (w.attach - rig.com)
        pull = w.anchor - point
        pull /= np.linalg.norm(pull, axis=1, keepdims=True)
        out[:, i] = np.einsum("nji,nj->ni", rotation, pull) * tensions[:, i : i + 1]
    return out
