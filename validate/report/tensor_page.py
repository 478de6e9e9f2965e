"""The page of a tensor fit (``tensor HANGINGS.toml --html FILE``): the tensor with its sigmas, the
principal moments and axes, each hanging's period against the model's, the tares, the warnings and
the hangings file as read. Built from the command's JSON report only, so the page shows what the
command computed."""

from __future__ import annotations

from pathlib import Path

from bifilar.rig.checks import read_text_file

from .html import number
from .page import Page
from .sections import Facts, Table, Text, Warnings

UNIT = "kg m^2"


def _pm(value, std) -> str:
    return number(value, 7) + ("" if std is None else f" ± {number(std, 2)}")


def tensor_page(report: dict, source: str) -> Page:
    t, s = report["tensor"], report["tensor_std"]
    p = report["principal"]
    page = Page(f"tensor from {Path(source).name}", f"object {number(report['object']['mass'], 6)} kg, "
                                                    f"{len(report['hangings'])} hangings")
    page.add(Table(f"Tensor about the object's COM, object axes ({UNIT})", ["", "x", "y", "z"],
                   [[axis] + [_pm(t[i][k], None if s is None else s[i][k]) for k in range(3)]
                    for i, axis in enumerate("xyz")]))
    page.add(Table("Principal moments and axes (object axes)", ["", f"moment ({UNIT})", "axis"],
                   [[str(k + 1), _pm(p["moments"][k], None if p["moments_std"] is None else p["moments_std"][k]),
                     ", ".join(f"{row[k]:+.4f}" for row in p["axes"])] for k in range(3)]))
    page.add(Table("Hangings", ["name", "rig", "period used (s)", "sigma (s)", "from", "model (s)", "residual (sigma)",
                                "tare"],
                   [[h["name"], h["rig"], number(h["period"], 9), number(h["period_std"], 2), h["period_source"],
                     number(h["model_period"], 9),
                     "" if h["residual_sigmas"] is None else f"{h['residual_sigmas']:+.2f}",
                     "" if h["tare"] is None else str(h["tare"])] for h in report["hangings"]],
                   note="" if report["chi2_per_dof"] is None else
                   f"chi^2 per degree of freedom {number(report['chi2_per_dof'], 3)}"))
    if report["tares"]:
        page.add(Table("Tares (each measured once, shared by its hangings)", ["", "rig", f"moment ({UNIT})",
                                                                              "period (s)", "hangings"],
                       [[str(k), f["rig"], _pm(f["moment"], f["moment_std"]), number(f["period"], 9),
                         ", ".join(f["hangings"])] for k, f in enumerate(report["tares"])]))
    page.add(Warnings("Warnings", report["flags"]),
             Text("Hangings file", [f"{source}:", read_text_file(source)]),
             Facts("Covariance", [("order", ", ".join(report["components"])),
                                  ("matrix", "none" if report["covariance"] is None else
                                   "; ".join(" ".join(f"{v:.3e}" for v in row) for row in report["covariance"]))]))
    return page


def write_tensor_html(path: str | Path, report: dict, source: str) -> Path:
    """Write the page (see the module docstring) whole."""
    return tensor_page(report, source).write(path)
