"""``identify --png``: each record with its fit, the residuals, and the per-cycle period against amplitude.

One row of three panels per trial (matplotlib, Agg): the record (rejected samples marked) with the
fitted model; the residuals; the period of each cycle of the record (rising crossings of the signal
cleaned of the fitted offset, drift and second mode) against that cycle's amplitude, beside the
fitted law T0 (1 + s A^2) (the series of the fitted law, for reading only).
"""

from __future__ import annotations


import numpy as np

from ..report.figures import png_bytes, pyplot
from ..trajectory import atomic_write_bytes


def draw(trials, path: str) -> None:
    """Write the figure of ``trials`` (:class:`bifilar.identification.trials.Trial`) to ``path`` whole."""
    atomic_write_bytes(path, render(trials))


def render(trials) -> bytes:
    """The figure of ``trials`` as PNG bytes (``identify --png``, and the fit in ``identify --html``)."""
    plt = pyplot()

    from bifilar.identification.signals import cycles

    fig, axes = plt.subplots(len(trials), 3, figsize=(15, 3.6 * len(trials)), squeeze=False)
    for row, tr in zip(axes, trials):
        fit = tr.fit
        name = tr.record.source.rsplit("/", 1)[-1]
        row[0].plot(fit.t[fit.kept], fit.y[fit.kept], ".", ms=2, color="0.5", label="record")
        row[0].plot(fit.t, fit.fitted, "-", lw=0.8, color="C0", label="fit")
        if fit.outliers.size:
            row[0].plot(fit.t[~fit.kept], fit.y[~fit.kept], "x", color="C3", label=f"{fit.outliers.size} rejected")
        row[0].set(title=f"{name}: T0 = {fit.period:.7g} +- {fit.period_std:.2g} s", xlabel="t (s)",
                   ylabel=tr.record.kind)
        row[0].legend(loc="upper right", fontsize=8)
        row[1].plot(fit.t[fit.kept], (fit.y - fit.fitted)[fit.kept], ".", ms=2, color="C1")
        row[1].set(title=f"residuals (rms {fit.rms:.3g}, block {fit.block})", xlabel="t (s)")
        periods, amps = cycles(fit)
        row[2].plot(amps, periods, "o", ms=3, label="each cycle")
        a = np.linspace(0.0, max(amps.max(), 1e-9), 100) if amps.size else np.zeros(1)
        scale = 1.0 if tr.record.kind != "rate" else 2.0 * np.pi / fit.period  # a rate's peak is A omega
        row[2].plot(a, fit.period * (1.0 + fit.amplitude_coefficient * (a / scale) ** 2), "-",
                    label=f"T0 (1 + {fit.amplitude_coefficient:.4g} A^2)")
        row[2].set(title="period against amplitude", xlabel=f"cycle amplitude ({tr.record.kind} units)",
                   ylabel="period (s)")
        row[2].legend(fontsize=8)
    return png_bytes(fig)
