"""A plausible swing in the wrong unit: an angle in degrees (or a rate in deg/s) read as rad.

A 0.02 rad swing written in degrees and read as radians is a 1.15 rad swing: one the rig can make, so
:func:`.pipeline.swing_problem` cannot refuse it. Its amplitude alone cannot tell, and neither can a rate
record's amplitude against the fitted angle's times the frequency (the angle is the rate's integral, in
the rate's unit). What can tell is how the period changes as the swing decays: at 1.15 rad the rig's law
lengthens it by several per cent over the swept amplitudes, at 0.02 rad by ~1e-4 of that. The fit learns
the real law's excess ds over the ideal coefficient s from the record's own T(A) (:mod:`.law`), with a
prior of ``law_sigma`` s; what the record alone says of ds (the prior taken out of the fit's posterior,
``learned`` = the data's share of its precision) is weighed under two hypotheses:

* the unit is right: ds ~ N(0, (law_sigma s)^2), a real rig's excess;
* the values are degrees: the true swing is A pi / 180, whose law is flat, so the record asks for the
  excess that cancels the ideal law, ds = -s (1 - (pi / 180)^2), up to the law's terms beyond A^2 at
  the largest swing, which the fit shares between ds and its higher terms (that part is this
  expectation's doubt).

Both hypotheses carry the data's own sigma of ds. The record is flagged where the Bayes factor for
degrees is past :data:`BAYES_FACTOR` and degrees explain it (chi^2 below the :data:`FITS` quantile): a
record that decays too little, or too noisy, for its ds to be known to well under s says nothing.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.stats import chi2

from .fit import OscillationFit

BAYES_FACTOR = 100.0  # decisive on Jeffreys' scale: a unit mistake is rare, a false alarm costs a re-check
FITS = 0.99  # the degrees hypothesis must itself explain the record's ds at this chi^2 quantile (1 dof)
_DEGREE = math.pi / 180.0


def degrees_evidence(fit: OscillationFit, law_sigma: float) -> tuple[float, float, float] | None:
    """(2 ln B, chi^2 if rad, chi^2 if degrees) of a fit of an angle or rate record read in rad, B the
    Bayes factor for degrees read as rad (module docstring); None where the record does not know its ds
    (no law, no scale, nothing learned)."""
    law = fit.law
    if fit.amplitude is None or law.ideal is None or law.ideal <= 0.0 or law.learned <= 1e-9:
        return None
    s, top = law.ideal, fit.amplitude[0]
    data_var = law.excess_std**2 / law.learned  # posterior precision = data's + prior's
    data_ds = law.excess / law.learned  # the posterior mean is the data's, shrunk by ``learned``
    a, _, ideal = fit.law_curve
    higher = (float(np.interp(top, a, ideal)) / fit.period - 1.0) / top**2 - s  # the law beyond A^2, per A^2
    rad_var = data_var + (law_sigma * s) ** 2
    deg_var = data_var + higher**2
    rad = data_ds**2 / rad_var
    deg = (data_ds + s * (1.0 - _DEGREE**2)) ** 2 / deg_var
    return rad + math.log(rad_var) - deg - math.log(deg_var), rad, deg


def degrees_read_as_rad(fit: OscillationFit, kind: str, law_sigma: float) -> str:
    """A flag's text (without the file's name) if the record is likely in degrees (deg/s) read as rad
    (rad/s), else ''."""
    found = degrees_evidence(fit, law_sigma)
    if found is None:
        return ""
    evidence, _, deg = found
    if evidence < 2.0 * math.log(BAYES_FACTOR) or deg > chi2.ppf(FITS, 1):
        return ""
    top, odds = fit.amplitude[0], 0.5 * evidence
    unit = "deg/s" if kind == "rate" else "degrees"
    said = f"{math.exp(odds):.0f}:1" if odds < math.log(1e6) else "over 1e6:1"
    return (f"likely unit mistake: the period changes with the swing as a {top * _DEGREE:.3g} rad swing's would, "
            f"not as the {top:.3g} rad the unit implies (odds {said}): are the values in {unit} (--angle-unit deg)?")
