"""Waypoint targets: a smooth interpolation through recorded samples (systems/task/targets.py)."""

import timeit

import numpy as np
import pytest

from ptint_drake.systems.task.targets import LinearTarget, WaypointTarget

TIMES = [0.0, 0.4, 1.1, 1.5, 2.6]
POSITIONS = [[0.3, -0.15, 0.15], [0.31, -0.1, 0.17], [0.28, -0.02, 0.2], [0.25, 0.03, 0.18],
             [0.27, 0.12, 0.15]]


def _numeric_derivative(f, t, h=1e-6):
    return (f(t + h) - f(t - h)) / (2 * h)


def test_interpolates_samples_exactly():
    w = WaypointTarget(TIMES, POSITIONS)
    for t, x in zip(TIMES, POSITIONS):
        np.testing.assert_allclose(w.evaluate(t)[0:3], x, rtol=0, atol=1e-15)


def test_derivatives_are_consistent_and_c2_at_knots():
    w = WaypointTarget(TIMES, POSITIONS)
    for t in np.linspace(-0.5, 3.0, 57):
        d = w.evaluate(t)
        for k in range(3):  # each block is the derivative of the previous one, except
            # where it jumps: acceleration at the two ends, jerk at every knot
            near = TIMES if k == 2 else ([TIMES[0], TIMES[-1]] if k == 1 else [])
            if any(abs(t - tk) < 1e-5 for tk in near):
                continue
            np.testing.assert_allclose(
                _numeric_derivative(lambda s, k=k: w.evaluate(s)[3 * k:3 * k + 3], t), d[3 * k + 3:3 * k + 6],
                atol=1e-5)
    eps = 1e-9
    for t in TIMES[1:-1]:  # interior knots: position, velocity, acceleration continuous
        left, right = w.evaluate(t - eps), w.evaluate(t + eps)
        np.testing.assert_allclose(left[0:9], right[0:9], atol=1e-6)


def test_constant_velocity_extrapolation_is_c1():
    w = WaypointTarget(TIMES, POSITIONS)
    for t_end, outside in ((TIMES[0], -1.0), (TIMES[-1], 1.0)):
        inside, edge = w.evaluate(t_end - 1e-9 * outside), w.evaluate(t_end)
        np.testing.assert_allclose(inside[0:6], edge[0:6], atol=1e-7)  # C¹ at the ends
        far = w.evaluate(t_end + outside)
        np.testing.assert_allclose(far[0:3], edge[0:3] + edge[3:6] * outside, atol=1e-15)
        np.testing.assert_allclose(far[3:6], edge[3:6], atol=1e-15)
        np.testing.assert_array_equal(far[6:12], np.zeros(6))


@pytest.mark.parametrize("times", [[0.0, 1.0], [0.0, 0.3, 1.0], [0.2, 0.5, 0.6, 1.7, 3.0, 3.1]])
def test_samples_on_a_line_give_that_line(times):
    line = LinearTarget([0.3, -0.15, 0.15], [0.0, 0.1, -0.03])
    w = WaypointTarget(times, [line.evaluate(t)[0:3] for t in times])
    for t in np.linspace(times[0] - 1.0, times[-1] + 1.0, 41):
        np.testing.assert_allclose(w.evaluate(t), line.evaluate(t), atol=1e-13)


@pytest.mark.parametrize("time, position, field", [
    ([0.0], [[0, 0, 0]], "time"),
    ([0.0, 0.0, 1.0], [[0, 0, 0]] * 3, "time"),
    ([0.0, 2.0, 1.0], [[0, 0, 0]] * 3, "time"),
    ([0.0, float("nan")], [[0, 0, 0]] * 2, "time"),
    ([0.0, 1.0], [[0, 0], [0, 0]], "position"),
    ([0.0, 1.0], [[0, 0, 0]], "position"),
    ([0.0, 1.0], [[0, 0, 0], [0, float("inf"), 0]], "position"),
    ([0.0, 1.0], [[0, 0, 0], [0, 0]], "position"),
])
def test_validation_names_the_field(time, position, field):
    with pytest.raises(ValueError) as info:
        WaypointTarget(time, position)
    assert str(info.value).startswith(f"{field}: ")
    assert "\n" not in str(info.value)


def test_evaluate_is_fast():
    w = WaypointTarget(np.linspace(0, 10, 200), np.random.default_rng(0).normal(size=(200, 3)))
    per_call = min(timeit.repeat(lambda: w.evaluate(4.321), number=2000, repeat=3)) / 2000
    assert per_call < 50e-6  # measured ≈ 4 µs; a Drake trajectory call per derivative is ≈ 4× that
