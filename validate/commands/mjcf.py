"""``python -m validate mjcf RIG... --out DIR``: MuJoCo models of rigs, ``DIR/<rig>/<rig>.xml`` and
``DIR/<rig>/scene.xml`` (:mod:`validate.engines.mjcf`; a hinge rig's by :mod:`validate.engines.mujoco_hinge`);
the rigs' names must differ."""

from __future__ import annotations

from pathlib import Path

from bifilar.rig import RigError

from ..statuses import OK, epilog
from .shared import load


def add_parser(subparsers) -> None:
    """Register the ``mjcf`` subcommand on the CLI's subparsers."""
    p = subparsers.add_parser("mjcf", help="write MuJoCo models of rigs: DIR/<rig>/<rig>.xml and DIR/<rig>/scene.xml",
                              epilog=epilog("mjcf", ("python -m validate mjcf asymmetric plate --out out/",)))
    p.add_argument("rigs", nargs="+", metavar="RIG", help="rig files (TOML) or shipped rigs' names ('list --rigs'); "
                                                         "their names must differ")
    p.add_argument("--out", required=True, metavar="DIR", help="folder that receives one folder per rig name")


def run(args) -> int:
    """Load every rig first (so a bad one writes nothing), then write and print each model file."""
    from bifilar.rig.hinge import HingeRig

    from ..engines import mjcf, mujoco_hinge

    loaded = [load(path, hinge=True)[0] for path in args.rigs]
    names: dict[str, str] = {}
    for path, rig in zip(args.rigs, loaded):
        if rig.name in names:
            raise RigError(path, "name", f"{rig.name!r} is also the name of {names[rig.name]}: each rig's model "
                           f"goes to {args.out}/<name>/, so the names must differ")
        names[rig.name] = path
    for rig in loaded:
        if isinstance(rig, HingeRig):
            mujoco_hinge.build_spec(rig)  # an unknown moment or stiffness is refused before anything is written
    for rig in loaded:
        write = mujoco_hinge.write_model_files if isinstance(rig, HingeRig) else mjcf.write_model_files
        for written in write(rig, Path(args.out) / rig.name):
            print(written)
    return OK
