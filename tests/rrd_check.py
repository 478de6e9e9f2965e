"""Checks of a written .rrd: rerun's own ``rerun rrd verify`` passes on it, and its blueprint (the
layout the viewer opens with) read back with ``rerun.chunk.RrdReader``."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

from rerun.chunk import RrdReader


def verify(path: Path) -> None:
    """``rerun rrd verify PATH`` (the CLI that ships with rerun-sdk) exits 0."""
    rerun = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")
    assert rerun, "the rerun CLI of rerun-sdk is not installed"
    # rerun's CLI sends usage analytics except on CI (the CI variable): none leave this machine.
    proc = subprocess.run([rerun, "rrd", "verify", str(path)], capture_output=True, text=True, timeout=120,
                          env={**os.environ, "CI": os.environ.get("CI", "true")})
    assert proc.returncode == 0, proc.stdout + proc.stderr


def blueprint(path: Path) -> dict[str, dict[str, list]]:
    """The default blueprint: entity (``time_panel``, ``view/<id>``, ...) -> component -> values."""
    reader = RrdReader(path)
    (store,) = reader.blueprints()
    out: dict[str, dict[str, list]] = {}
    for chunk in reader.stream(store=store):
        batch = chunk.to_record_batch()
        entry = out.setdefault(chunk.entity_path.lstrip("/"), {})
        for name in batch.schema.names:
            if ":" in name:
                entry.setdefault(name.split(":", 1)[1], []).extend(batch.column(name).to_pylist())
    return out


def views(path: Path) -> dict[str, tuple[str, str]]:
    """Each view of the blueprint: its name -> (its class: ``3D``, ``TimeSeries``, ``Dataframe``, ...;
    its origin)."""
    out = {}
    for entity, entry in blueprint(path).items():
        if entity.startswith("view/") and entity.count("/") == 1:
            out[_flat(entry["display_name"])] = (_flat(entry["class_identifier"]), _flat(entry["space_origin"]))
    return out


def timeline(path: Path) -> str:
    """The timeline the viewer opens on."""
    return _flat(blueprint(path)["time_panel"]["timeline"])


def _flat(values: list):
    value = values[0]
    while isinstance(value, list):
        value = value[0]
    return value
