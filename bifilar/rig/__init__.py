"""The rig: its file (body, wires, initial state, uncertainty, the air around the body), the field checks,
a hinge rig (a compound or torsion pendulum: hinge.py), and its statics (rest pose, static tensions, the
initial state both engines start from)."""

from bifilar.rig.file import Rig, RigError, Uncertainty, Wire, load_rig, rig_from_dict
from bifilar.rig.hinge import HingeRig

__all__ = ["HingeRig", "Rig", "RigError", "Uncertainty", "Wire", "load_rig", "rig_from_dict"]
