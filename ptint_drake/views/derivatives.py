"""Derivatives of a logged signal for the figures: a cubic spline onto a uniform grid, then
a Savitzky–Golay filter (the integrator's steps are not uniform, and its error, relative
1e-4, would dominate a finite-difference jerk).

The filter (``savgol_derivative``) is the Savitzky–Golay least-squares polynomial smoother
(A. Savitzky and M. J. E. Golay, Anal. Chem. 36(8), 1964), with the edges treated as SciPy's
``scipy.signal.savgol_filter`` does for ``mode="interp"``: equal to it to 1e-12
(tests/unit/test_derivatives.py), without importing ``scipy.signal`` (≈ 0.7–1.3 s: it imports
``scipy.stats``) in the process that draws the figure.
"""

from __future__ import annotations

from math import factorial

import numpy as np
from numpy.polynomial import polynomial as P
from pydrake.trajectories import PiecewisePolynomial


def savgol_derivative(v: np.ndarray, window: int, order: int, deriv: int, delta: float) -> np.ndarray:
    """The ``deriv``-th derivative of the samples ``v`` (spacing ``delta``, along axis 0) by a
    Savitzky–Golay filter: a polynomial of degree ``order`` fitted by least squares to the
    ``window`` (odd) samples around each one, differentiated at its centre.  The first and last
    ``window // 2`` samples take the derivative of the polynomial fitted to the first (last)
    ``window`` samples, at their own places (SciPy's ``mode="interp"``)."""
    half = window // 2
    # weights w with w · v[i - half : i + half + 1] = the fitted polynomial's derivative at i:
    # the minimum-norm solution of A w = e, A[p, j] = (j - half)^p, e[p] = deriv! / δ^deriv at p = deriv
    offsets = np.arange(-half, half + 1, dtype=float)
    vandermonde = offsets[np.newaxis, :] ** np.arange(order + 1)[:, np.newaxis]
    target = np.zeros(order + 1)
    target[deriv] = factorial(deriv) / delta**deriv
    weights = np.linalg.lstsq(vandermonde, target, rcond=None)[0]
    n = len(v)
    out = np.empty(v.shape, dtype=float)
    out[half:n - half] = np.lib.stride_tricks.sliding_window_view(v, window, axis=0) @ weights
    local = np.arange(window, dtype=float)  # the edge windows: first and last ``window`` samples
    for rows, start in ((slice(0, half), 0), (slice(n - half, n), n - window)):
        coef = P.polyder(P.polyfit(local, v[start:start + window], order), deriv)
        out[rows] = P.polyval(local[rows.start - start:rows.stop - start], coef).T / delta**deriv
    return out


def uniform_derivatives(t: np.ndarray, xdot: np.ndarray, dt: float = 1e-3, window_s: float = 0.021):
    """(t_u, ẋ, ẍ, x⃛) on a uniform grid from per-step samples of ẋ (axis 0: time).

    The samples are put on a uniform ``dt`` grid by a cubic spline with not-a-knot ends
    (Drake's ``PiecewisePolynomial.CubicWithContinuousSecondDerivatives``: SciPy's default
    ``CubicSpline`` to rounding, tests/unit/test_derivatives.py, without importing
    ``scipy.interpolate``, ≈ 0.2 s, where a run's figures are drawn), then differentiated with
    a Savitzky–Golay filter (cubic, ``window_s`` wide).  Two distinct times give a line.
    """
    keep = np.concatenate([[True], np.diff(t) > 1e-12])
    breaks, samples = np.asarray(t, dtype=float)[keep], np.asarray(xdot, dtype=float)[keep]
    spline = PiecewisePolynomial.FirstOrderHold(breaks, samples.T) if len(breaks) < 3 else \
        PiecewisePolynomial.CubicWithContinuousSecondDerivatives(breaks, samples.T, False)
    t_u = np.arange(t[0], t[-1], dt)
    v = spline.vector_values(t_u).T
    n = max(5, int(round(window_s / dt)) | 1)
    if len(t_u) <= n:
        return t_u, v, *(spline.derivative(k).vector_values(t_u).T for k in (1, 2))
    return t_u, v, savgol_derivative(v, n, 3, 1, dt), savgol_derivative(v, n, 3, 2, dt)
