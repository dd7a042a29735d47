"""The figures' Savitzky–Golay derivative equals SciPy's ``savgol_filter`` (mode "interp")."""

import numpy as np
import pytest
from scipy.signal import savgol_filter

from ptint_drake.views.derivatives import savgol_derivative, uniform_derivatives


@pytest.mark.parametrize("shape", [(400,), (300, 3)])
@pytest.mark.parametrize(("window", "order", "deriv"),
                         [(21, 3, 1), (21, 3, 2), (5, 3, 2), (11, 2, 1), (9, 4, 3)])
def test_savgol_derivative_equals_scipy(shape, window, order, deriv):
    rng = np.random.default_rng(7)
    t = np.arange(shape[0]) * 1e-3
    v = np.sin(7.0 * t).reshape(-1, *([1] * (len(shape) - 1))) + 0.01 * rng.standard_normal(shape)
    ours = savgol_derivative(v, window, order, deriv, 1e-3)
    ref = savgol_filter(v, window, order, deriv=deriv, delta=1e-3, axis=0)
    assert ours.shape == ref.shape
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(ref)))


def test_uniform_derivatives_of_a_cubic_are_exact():
    """A cubic velocity on a non-uniform grid: the spline and a cubic filter reproduce its
    derivatives (edges included), so the figure's acceleration and jerk are the signal's."""
    t = np.sort(np.random.default_rng(3).uniform(0.0, 0.5, 700))
    t[0], t[-1] = 0.0, 0.5
    xdot = np.column_stack([t**3 - t, 2.0 * t**2, -t**3])
    t_u, v, a, j = uniform_derivatives(t, xdot)
    np.testing.assert_allclose(a, np.column_stack([3 * t_u**2 - 1, 4 * t_u, -3 * t_u**2]), atol=1e-9)
    np.testing.assert_allclose(j, np.column_stack([6 * t_u, 4 + 0 * t_u, -6 * t_u]), atol=1e-6)


@pytest.mark.parametrize("n", [2, 3, 4, 60, 1400])
def test_uniform_grid_spline_is_scipys_not_a_knot_cubic(n):
    """The resampling spline is SciPy's default ``CubicSpline`` (not-a-knot ends) to rounding,
    with repeated times dropped; two distinct times give the line through them."""
    from scipy.interpolate import CubicSpline

    rng = np.random.default_rng(n)
    t = np.sort(rng.uniform(0.0, 0.3, n))
    t[0] = 0.0
    t = np.insert(t, 1, t[1])  # a repeated time (an event: two log rows)
    xdot = np.column_stack([np.sin(9 * t), np.cos(4 * t), t**3])
    t_u, v, _, _ = uniform_derivatives(t, xdot)
    keep = np.r_[True, np.diff(t) > 1e-12]
    ref = CubicSpline(t[keep], xdot[keep], axis=0)(t_u)
    np.testing.assert_allclose(v, ref, rtol=0, atol=1e-13)
