"""Derivatives of a logged signal for the figures: a cubic spline onto a uniform grid, then
a Savitzky–Golay filter (the integrator's steps are not uniform, and its error, relative
1e-4, would dominate a finite-difference jerk).

The filter is SciPy's ``savgol_filter``, imported where it is used (``scipy.signal`` costs
about 0.2–0.8 s to import, so a run that draws no acceleration figure does not pay it).
"""

from __future__ import annotations

import numpy as np


def uniform_derivatives(t: np.ndarray, xdot: np.ndarray, dt: float = 1e-3, window_s: float = 0.021):
    """(t_u, ẋ, ẍ, x⃛) on a uniform grid from per-step samples of ẋ.

    The samples are put on a uniform ``dt`` grid by a cubic spline, then
    differentiated with a Savitzky–Golay filter (cubic, ``window_s`` wide).
    """
    from scipy.interpolate import CubicSpline  # noqa: PLC0415  (only where a figure needs it)
    from scipy.signal import savgol_filter  # noqa: PLC0415  (≈ 0.2–0.8 s to import: only here)

    keep = np.concatenate([[True], np.diff(t) > 1e-12])
    spline = CubicSpline(t[keep], xdot[keep], axis=0)
    t_u = np.arange(t[0], t[-1], dt)
    v = spline(t_u)
    n = max(5, int(round(window_s / dt)) | 1)
    if len(t_u) <= n:
        return t_u, v, spline(t_u, 1), spline(t_u, 2)
    return (t_u, v, savgol_filter(v, n, 3, deriv=1, delta=dt, axis=0),
            savgol_filter(v, n, 3, deriv=2, delta=dt, axis=0))
