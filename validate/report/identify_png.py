"""``identify --png``: each record with its fit, the residuals, and each cycle's period against amplitude.

One row of three panels per trial (matplotlib, Agg): the record (samples left out marked) with the
fitted model; the residuals; the period between neighbouring cycles (from their measured phases)
against the cycle's peak amplitude, beside the fitted law T0 R(A) E(A) and the ideal one T0 R(A), in
the same units: rad, or the record's own units where a proportional record's scale is unknown (then
no law is drawn: it cannot be applied).
"""

from __future__ import annotations


import numpy as np

from ..report.figures import png_bytes, pyplot
from ..trajectory import atomic_write_bytes


def draw(trials, path: str) -> None:
    """Write the figure of ``trials`` (:class:`bifilar.identification.records.pipeline.Trial`) to ``path`` whole."""
    atomic_write_bytes(path, render(trials))


def render(trials) -> bytes:
    """The figure of ``trials`` as PNG bytes (``identify --png``, and the fit in ``identify --html``)."""
    plt = pyplot()
    fig, axes = plt.subplots(len(trials), 3, figsize=(15, 3.6 * len(trials)), squeeze=False)
    for row, tr in zip(axes, trials):
        fit = tr.fit
        name = tr.record.source.rsplit("/", 1)[-1]
        row[0].plot(fit.t[fit.kept], fit.y[fit.kept], ".", ms=2, color="0.5", label="record")
        row[0].plot(fit.t, fit.fitted, "-", lw=0.8, color="C0", label="fit")
        if (~fit.kept).any():
            row[0].plot(fit.t[~fit.kept], fit.y[~fit.kept], "x", ms=3, color="C3",
                        label=f"{int((~fit.kept).sum())} not used")
        row[0].set(title=f"{name}: T0 = {fit.period:.7g} +- {fit.period_std:.2g} s", xlabel="t (s)",
                   ylabel=tr.record.kind)
        row[0].legend(loc="upper right", fontsize=8)
        row[1].plot(fit.t[fit.kept], (fit.y - fit.fitted)[fit.kept], ".", ms=2, color="C1")
        row[1].set(title=f"residuals (rms {fit.rms:.3g}, block {fit.block} cycles)", xlabel="t (s)")
        ok = np.isfinite(fit.cycle_period)
        middle = 0.5 * (fit.cycle_amplitude[:-1] + fit.cycle_amplitude[1:])
        row[2].plot(middle[ok], fit.cycle_period[ok], "o", ms=3, label="between neighbouring cycles")
        a, fitted, ideal = fit.law_curve
        known = fit.amplitude is not None or tr.record.kind != "proportional"
        unit = "rad" if known else f"{tr.record.column} units, scale unknown"
        if fit.law.ideal is not None and known:
            row[2].plot(a, fitted, "-", color="C0", label=f"fitted law (excess {fit.law.excess / fit.law.ideal:+.1%})")
            row[2].plot(a, ideal, "--", color="0.4", label="ideal law")
        else:
            row[2].axhline(fit.period, color="C0", label="T0 (no law applied)")
        row[2].set(title="period against amplitude", xlabel=f"peak amplitude ({unit})", ylabel="period (s)")
        row[2].legend(fontsize=8)
    return png_bytes(fig)
