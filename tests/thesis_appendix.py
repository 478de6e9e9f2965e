"""The thesis's appendix B (seed 000) as printed, entry by entry, for comparison with the kernel.

Each function takes theta, theta' and the parameters (b, b', l, r, lam) and returns the printed
expression. Entries that are wrong in print are kept as printed here, so that the test shows the
typo; docs/thesis-corrections.md gives the corrected forms.
"""

import numpy as np


def _sc(th):
    s = np.sin(th)
    c = np.cos(th)
    return s, c


def printed_beta(th, b, bp, l):
    """beta of (5.1.3) as printed (it is dg/dtheta divided by 2 b'^2)."""
    (s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5) = _sc(th)
    x = l / bp * s2 * c3 + s4 * c5
    y = -b / bp + l / bp * s2 * s3 + c4 * c5
    z = -l / bp * c2 + s5
    return np.array([
        0.0,
        l / bp * (c2 * c3 * x + c2 * s3 * y + s2 * z),
        l / bp * (-s2 * s3 * x + s2 * c3 * y),
        c4 * c5 * x - s4 * c5 * y,
        s4 * s5 * x + c4 * s5 * y - c5 * z,
    ])


def printed_V(th, l, r, lam):
    """V of (5.1.17) as printed."""
    (s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5) = _sc(th)
    sl, cl = np.sin(lam), np.cos(lam)
    return np.array([
        [r * sl * (c1 * c4 - s1 * s4 * s5), l * c2 * c3, -l * s2 * s3,
         r * (sl * (-s1 * s4 + c1 * c4 * s5) + cl * c4 * c5), r * (-cl * s4 * s5 + sl * c1 * s4 * c5)],
        [-r * sl * (c1 * s4 + s1 * c4 * s5), l * c2 * s3, l * s2 * c3,
         -r * (sl * s4 * c5 + sl * (s1 * c4 + c1 * s4 * s5)), r * (sl * c1 * c4 * c5 - cl * c4 * s5)],
        [r * sl * s1 * c5, l * s2, 0.0, 0.0, r * (cl * c5 + sl * c1 * s5)],
    ])


def printed_Vdot(th, dth, l, r, lam):
    """dV/dt of (5.1.18) as printed."""
    (s1, s2, s3, s4, s5), (c1, c2, c3, c4, c5) = _sc(th)
    d1, d2, d3, d4, d5 = dth
    sl, cl = np.sin(lam), np.cos(lam)
    return np.array([
        [-r * sl * ((s1 * c4 + c1 * s4 * s5) * d1 + (c1 * s4 + s1 * c4 * s5) * d4 + s1 * s4 * c5 * d5),
         -l * (s2 * c3 * d2 + c2 + s3 * d3),
         -l * (c2 * s3 * d2 + s2 * c3 * d3),
         r * (-sl * (c1 * s4 + s1 * c4 * s5) * d1 - (sl * s1 * c4 + sl * c1 * s4 * s5 + cl * s4 * c5) * d4
              + (sl * c1 * c4 * c5 - cl * c4 * s5) * d5),
         r * (-sl * s1 * s4 * c5 * d1 + (sl * c1 * c5 - cl * s5) * c4 * d4 - (cl * s4 * c5 + sl * c1 * s4 * s5) * d5)],
        [-r * sl * ((c1 * c4 * s5 - s1 * s4) * d1 + (c1 * c4 - s1 * s4 * s5) * d4 + s1 * c4 * c5 * d5),
         l * (-s2 * s3 * d2 + c2 * c3 * d3),
         l * (c2 * c3 * d2 - s2 * s3 * d3),
         -r * (sl * (c1 * c4 - s1 * s4 * s5) * d1 + (cl * c4 * c5 - sl * s1 * s4 + sl * c1 * c4 * s5) * d4
               + (sl * c1 * s4 * c5 - cl * s4 * s5) * d5),
         r * (-sl * s1 * c4 * c5 * d1 + (cl * s5 - sl * c1 * c5) * s4 * d4 - (sl * c1 * c4 * s5 + cl * c4 * c5) * d5)],
        [r * sl * (c1 * c5 * d1 - s1 * s5 * d5), l * c2 * d2, 0.0, 0.0,
         r * (-sl * s1 * s5 * d1 + (sl * c1 * c5 - cl * s5) * d5)],
    ])
