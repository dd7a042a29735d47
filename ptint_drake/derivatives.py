"""Derivatives of a logged signal for the figures: a cubic spline onto a uniform grid, then
a Savitzky–Golay filter (the integrator's steps are not uniform, and its error, relative
1e-4, would dominate a finite-difference jerk).

The Savitzky–Golay filter is computed here with NumPy (a least-squares polynomial per
window, evaluated at the window's centre; the first and last half-windows evaluate the
polynomial fitted to the first and last whole window), which is what
``scipy.signal.savgol_filter(..., mode="interp")`` computes, without importing
``scipy.signal`` (≈ 0.8 s of a ``ptint run``).
"""

from __future__ import annotations

import math

import numpy as np


def savgol_weights(window: int, order: int, deriv: int, positions) -> np.ndarray:
    """(len(positions), window) weights: row i applied to a window of samples (unit spacing)
    gives the ``deriv``-th derivative, at sample ``positions[i]`` of the window, of the
    least-squares polynomial of degree ``order`` through them."""
    centre = 0.5 * (window - 1)
    x = np.arange(window) - centre
    powers = np.arange(order + 1)
    fit = np.linalg.pinv(x[:, None] ** powers)  # coefficients from samples
    p = np.asarray(positions, dtype=float)[:, None] - centre
    scale = np.array([math.perm(j, deriv) if j >= deriv else 0 for j in powers], dtype=float)
    derivative = scale * p ** np.maximum(powers - deriv, 0)
    return derivative @ fit


def savgol(y: np.ndarray, window: int, order: int, deriv: int = 0, delta: float = 1.0) -> np.ndarray:
    """Savitzky–Golay smoothing / derivative of ``y`` along axis 0 (odd ``window`` ≤ len(y))."""
    y = np.asarray(y, dtype=float)
    half = window // 2
    centre = savgol_weights(window, order, deriv, [half])[0]
    out = np.empty_like(y)
    windows = np.lib.stride_tricks.sliding_window_view(y, window, axis=0)  # (n - w + 1, ..., w)
    out[half:len(y) - half] = windows @ centre
    out[:half] = np.tensordot(savgol_weights(window, order, deriv, range(half)), y[:window], axes=1)
    out[len(y) - half:] = np.tensordot(savgol_weights(window, order, deriv, range(half + 1, window)),
                                       y[len(y) - window:], axes=1)
    return out / delta ** deriv


def uniform_derivatives(t: np.ndarray, xdot: np.ndarray, dt: float = 1e-3, window_s: float = 0.021):
    """(t_u, ẋ, ẍ, x⃛) on a uniform grid from per-step samples of ẋ.

    The samples are put on a uniform ``dt`` grid by a cubic spline, then
    differentiated with a Savitzky–Golay filter (cubic, ``window_s`` wide).
    """
    from scipy.interpolate import CubicSpline  # noqa: PLC0415  (only where a figure needs it)

    keep = np.concatenate([[True], np.diff(t) > 1e-12])
    spline = CubicSpline(t[keep], xdot[keep], axis=0)
    t_u = np.arange(t[0], t[-1], dt)
    v = spline(t_u)
    n = max(5, int(round(window_s / dt)) | 1)
    if len(t_u) <= n:
        return t_u, v, spline(t_u, 1), spline(t_u, 2)
    return t_u, v, savgol(v, n, 3, deriv=1, delta=dt), savgol(v, n, 3, deriv=2, delta=dt)
