"""The page of an identification (``identify ... --html FILE``): the moment with its uncertainty, the
warnings, each record's fit with its residuals and its period against amplitude beside the fitted
law, the variance budget, the check of the identified tensor, and the inputs (the options given and
the rig files as read).

Built from the command's typed result (:class:`bifilar.identification.measurement.Measurement`, the one
``--json`` prints as a dict, docs/identification.md) and its fitted trials, so the page shows what the
command computed and nothing else.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from .html import Raw, join, number, table, tag
from .page import Page, Section
from .sections import Facts, Table, Text, Warnings, figure

if TYPE_CHECKING:
    from bifilar.identification.measurement import Measurement

UNIT = "kg m^2"


def _pm(value, std, unit: str = "", digits: int = 9) -> str:
    text = number(value, digits)
    if std is not None:
        text += f" ± {number(std, 3)}"
    return f"{text} {unit}".strip()


def result_section(result: Measurement, title: str = "Result") -> Facts:
    a = result.axis
    items = [("rig", result.rig), (f"I_{a}{a}", _pm(result.inertia, result.std, UNIT))]
    if result.interval95:
        items.append(("95 % interval", f"{number(result.interval95[0], 9)} .. {number(result.interval95[1], 9)} "
                                       f"{UNIT} ({result.method})"))
    items += [("sigma: repeatability", number(result.std_repeatability, 3, UNIT)),
              ("sigma: rig geometry and mass", number(result.std_rig, 3, UNIT)),
              ("I / m", _pm(result.inertia_per_mass, result.std_per_mass, "m^2")),
              ("radius of gyration", _pm(result.radius_of_gyration, result.radius_of_gyration_std, "m", 6)),
              ("period at zero amplitude", _pm(result.period, result.period_std, "s") +
               f" ({result.period_std_source})"),
              ("d ln T / d ln I", number(result.sensitivity, 4)),
              ("start value", result.start_value)]
    if result.timed_period is not None:
        items.append(("period as timed", f"{number(result.timed_period, 9)} s at amplitude "
                                         f"{number(result.amplitude[0], 4)} rad"))
    if result.air is not None:
        items += [("without the air", _pm(result.air.inertia, result.air.std, UNIT)),
                  ("the air's share", f"{100.0 * result.air.share:.2f} % of the measured moment")]
    if len(result.trials) > 1:
        items.append(("between trials", f"std {number(result.pooled.between_trial_std, 3, UNIT)}, chi^2 per degree "
                                        f"of freedom {number(result.pooled.chi2_per_dof, 3)}"))
    return Facts(title, items)


def trials_table(trials: list[dict]) -> Raw:
    """The trials (their JSON objects, :meth:`Measurement.trial_dicts`) a row each."""
    rows = []
    for i, tr in enumerate(trials, start=1):
        amp = tr["amplitude"]
        second = tr["second_mode"]
        rows.append((i, tr["source"], _pm(tr["period"], tr["period_std"], "s"), _pm(tr["inertia"], tr["std"], UNIT),
                     "scale unknown" if amp is None else f"{number(amp[0], 3)} -> {number(amp[1], 3)}",
                     f"{number(tr['damping']['linear'], 3)} + {number(tr['damping']['quadratic'], 3)} |w|",
                     _law(tr["law"]), _halves(tr["halves"]),
                     number(tr["residual_rms"], 3), f"{tr['rejected']['samples']} of {tr['samples'] + tr['rejected']['samples']}",
                     "-" if second is None else f"{number(second['period'], 4)} s", _bound(tr)))
    return table(("trial", "record", "T0", "I", "amplitude (start -> end)", "damping", "amplitude law", "halves",
                  "residual rms", "left out", "second mode", "T0 sigma (record) / Cramér-Rao bound"), rows)


def _bound(trial: dict) -> str:
    """How far the record's T0 sigma is above the bound, and what makes it."""
    from bifilar.identification.measurement import sigma_shares

    if trial["crb_ratio"] is None:
        return "-"
    parts = "; ".join(f"{what} {100.0 * share:.0f} %" for what, share in sigma_shares(trial))
    return f"{trial['crb_ratio']:.2f}x ({trial['crb_noise']} noise)" + (f": {parts}" if parts else "")


def _law(law: dict) -> str:
    """The amplitude law of a trial: the coefficient used, and how much the record itself taught."""
    if law["ideal"] is None:
        return law["kind"]
    if law["excess_std"] == 0.0:
        return f"{number(law['ideal'], 4)} A^2 ({law['kind']}, held)"
    return (f"{number(law['coefficient'], 4)} A^2 ({law['kind']}; excess {100.0 * law['excess'] / law['ideal']:+.1f} "
            f"± {100.0 * law['excess_std'] / abs(law['ideal']):.1f} %, {100.0 * law['learned']:.0f} % learned)")


def _halves(halves) -> str:
    if halves is None:
        return "too short"
    return (f"{number(halves['first']['period'], 7)} / {number(halves['second']['period'], 7)} s, "
            f"z = {halves['z']:+.2f}")


class FitSection(Section):
    """Each record with its fit, its residuals and its period against amplitude (the fitted law)."""

    title = "Fit"
    open = True

    def __init__(self, result: Measurement):
        self.result = result
        self.trials = result.trials + (result.tare.trials if result.tare else ())

    def body(self) -> str:
        if not self.trials:
            return tag("p", "A measured period was given: no record was fitted.")
        from .identify_png import render

        caption = ("each record with its fit (rejected samples marked), the residuals, and each cycle's period "
                   "against its amplitude beside the fitted law T0 (1 + s A^2)")
        return join([figure(render(self.trials), caption), trials_table(self.result.trial_dicts())])


def budget_section(result: Measurement) -> Section:
    if not result.budget:
        return Text("Variance budget", ["No uncertainty was propagated: nothing to share out."])
    groups = sorted(result.budget, key=lambda g: -result.budget[g])
    rows = [(g, f"{100.0 * result.budget[g]:.2f} %", f"{100.0 * result.budget_per_mass[g]:.2f} %") for g in groups]
    return Table("Variance budget", ("uncertainty group", f"share of var(I_{result.axis * 2})", "share of var(I / m)"),
                 rows, note="Each [uncertainty] group's share of the variance (the period group is the repeatability).")


def tensor_section(result: Measurement) -> Table:
    rows = []
    for label, check in (("identified tensor", result.tensor_check),
                         ("without the air", result.air.tensor_check if result.air else None)):
        if check:
            rows.append((label, ", ".join(number(x, 6) for x in check.principal),
                         "yes" if check.positive_definite else "NO", "yes" if check.triangle else "NO"))
    return Table("Tensor check", ("tensor", f"principal moments ({UNIT})", "positive definite", "triangle inequality"),
                 rows, note="The rig file's tensor with the identified moment in place: a body's tensor is positive "
                            "definite and its principal moments obey the triangle inequality.",
                 row_classes=[None if r[2] == r[3] == "yes" else "fail" for r in rows])


class InputsSection(Section):
    """The command line and every rig file as read."""

    title = "Inputs"
    open = False

    def __init__(self, command: str, files: dict[str, str]):
        self.command, self.files = command, files

    def body(self) -> str:
        parts = [tag("p", "command:"), tag("pre", self.command)]
        for label, path in self.files.items():
            try:
                text = Path(path).read_text()
            except OSError as exc:
                text = f"(could not be read again: {exc.strerror})"
            parts += [tag("p", f"{label}: {path}"), tag("pre", text)]
        return join(parts)


def identify_page(result: Measurement, command: str, files: dict[str, str]) -> Page:
    """The page (see the module docstring); ``command`` the command line, ``files`` label -> rig file."""
    a = result.axis
    page = Page(f"identify {result.rig}: I_{a}{a}", f"{_pm(result.inertia, result.std, UNIT)}")
    flags = list(result.flags)
    page.add(result_section(result))
    if result.tare is not None:
        obj = result.object_part
        flags += [f"fixture: {f}" for f in result.tare.flags] + [f"object: {f}" for f in obj.flags]
        page.add(result_section(result.tare, "Fixture (tare)"), Facts("Object (rig minus fixture)", [
            ("mass", number(obj.mass, 6, "kg")),
            ("COM (body frame)", ", ".join(number(x, 6) for x in obj.com) + " m"),
            (f"I_{a}{a} about its own COM", _pm(obj.inertia, obj.std, UNIT))]))
    page.add(Warnings("Warnings", flags), FitSection(result), budget_section(result), tensor_section(result),
             InputsSection(command, files))
    return page


def write_identify_html(path: str | Path, result: Measurement, args) -> Path:
    """Write the page of an ``identify`` run (its result and its ``args``) whole."""
    import shlex

    files = {"rig": args.rig, **({"fixture": args.tare} if args.tare else {})}
    command = "python -m validate " + shlex.join(getattr(args, "argv", ["identify", args.rig, "..."]))
    return identify_page(result, command, files).write(path)
