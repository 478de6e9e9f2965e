"""Rotations by rotation vector for the rest-pose search's inner loop (:mod:`bifilar.rig.statics`):
exp([v]x) by Rodrigues' formula, the cross-product matrix, and the left Jacobian of SO(3) that gives
SLSQP its constraint slopes. Plain numpy on 3-vectors, cheaper per call than scipy's Rotation objects."""

from __future__ import annotations

import math

import numpy as np


def rotation(v: np.ndarray) -> np.ndarray:
    """exp([v]x) by Rodrigues' formula, I + sin t / t K + (1 - cos t) / t^2 K^2 (K = [v]x, t = |v|): the
    search's inner loop, where scipy's Rotation (a quaternion object per call) took two thirds of the
    time; the same matrix to rounding (tests/test_statics.py)."""
    t = float(np.linalg.norm(v))
    k = skew(v)
    if t < 1e-6:  # the series: 1 - t^2/6 and 1/2 - t^2/24
        return np.eye(3) + (1.0 - t * t / 6.0) * k + (0.5 - t * t / 24.0) * (k @ k)
    return np.eye(3) + math.sin(t) / t * k + (1.0 - math.cos(t)) / t**2 * (k @ k)


def skew(v: np.ndarray) -> np.ndarray:
    """[v]x, the matrix of the cross product v x ."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def left_jacobian(v: np.ndarray) -> np.ndarray:
    """J_l(v) = I + (1 - cos t) / t^2 K + (t - sin t) / t^3 K^2 (K = [v]x, t = |v|): exp([v + dv]x) =
    exp([J_l dv]x) exp([v]x) to first order, so d(R(v) r) / dv = -[R(v) r]x J_l(v)."""
    t = float(np.linalg.norm(v))
    k = skew(v)
    if t < 1e-6:  # the series: 1/2 - t^2/24 and 1/6 - t^2/120
        return np.eye(3) + (0.5 - t * t / 24.0) * k + (1.0 / 6.0 - t * t / 120.0) * (k @ k)
    return np.eye(3) + (1.0 - math.cos(t)) / t**2 * k + (t - math.sin(t)) / t**3 * (k @ k)
