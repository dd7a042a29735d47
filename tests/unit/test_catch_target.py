"""The catch world's moving target (issue 46, ``worlds.catch.target``): it reaches the ball's
estimated centre at exactly t_catch with the matched fraction of its velocity, its velocity and
acceleration are the derivatives of its position along a ballistic estimate (what the
prescribed-time law needs of a moving target), its matching ramp starts from rest on the ball's
path and asks for no more acceleration than its stated bound, the brake after the catch starts
where the catch ended and stops; and the held rule of ``outcome`` takes the squeezed foam ball."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from ptint_drake.worlds.catch import oracle
from ptint_drake.worlds.catch.ball import BALL_DIAMETER
from ptint_drake.worlds.catch.outcome import _held
from ptint_drake.worlds.catch.target import BRAKE_TIME, braking, catch_reference, close_time

G = np.array([0.0, 0.0, -9.81])
P0, V0 = np.array([1.6, 0.1, 1.0]), np.array([-2.4, -0.1, 2.0])


def ballistic(t: float) -> np.ndarray:
    """An exact ballistic estimate [p, v, a] at t (the estimator's model)."""
    return np.concatenate([P0 + V0 * t + 0.5 * G * t * t, V0 + G * t, G])


@pytest.mark.parametrize("m", [0.0, 0.3, 1.0])
def test_the_target_meets_the_ball_at_t_catch_with_the_matched_velocity(m):
    t_c = 0.7
    ref = catch_reference(ballistic(t_c), 0.0, m, 0.05)
    assert np.allclose(ref[0:3], ballistic(t_c)[0:3], atol=1e-12)
    assert np.allclose(ref[3:6], m * ballistic(t_c)[3:6], atol=1e-12)
    assert np.allclose(ref[6:9], 0.0)  # no acceleration left at the catch
    early = catch_reference(ballistic(0.2), t_c - 0.2, m, 0.2)  # before the ramp: at rest, on the path
    v_c = ballistic(t_c)[3:6]
    assert np.allclose(early[0:3], ballistic(t_c)[0:3] - 0.5 * m * 0.2 * v_c, atol=1e-9)
    assert np.allclose(early[3:9], 0.0)


def test_the_matching_ramp_asks_for_no_more_than_its_bound():
    t_c, m, tau = 0.7, 0.3, 0.2
    peak = max(np.linalg.norm(catch_reference(ballistic(t), t_c - t, m, tau)[6:9])
               for t in np.linspace(t_c - tau, t_c, 201))
    bound = 1.875 * m * np.linalg.norm(ballistic(t_c)[3:6]) / tau  # the docstring's
    assert bound * 0.99 < peak <= bound * (1 + 1e-9)


def test_the_targets_velocity_and_acceleration_are_its_derivatives():
    t_c, m, h = 0.7, 0.4, 1e-5
    ref = lambda t: catch_reference(ballistic(t), t_c - t, m, 0.2)  # noqa: E731
    for t in (0.45, 0.55, 0.62, 0.68):
        numeric_v = (ref(t + h)[0:3] - ref(t - h)[0:3]) / (2 * h)
        numeric_a = (ref(t + h)[3:6] - ref(t - h)[3:6]) / (2 * h)
        assert np.allclose(numeric_v, ref(t)[3:6], atol=1e-5)
        assert np.allclose(numeric_a, ref(t)[6:9], atol=1e-3)


def test_the_brake_starts_where_the_catch_ends_and_stops():
    at_catch = catch_reference(ballistic(0.7), 0.0, 0.3, 0.2)
    assert np.allclose(braking(at_catch, 0.0), at_catch)
    late = braking(at_catch, BRAKE_TIME)
    assert np.allclose(late[3:9], 0.0)
    assert np.allclose(late[0:3], at_catch[0:3] + 0.5 * at_catch[3:6] * BRAKE_TIME, atol=1e-12)
    h = 1e-6
    for tau in (0.2, 0.5, 0.8):
        step = braking(at_catch, (tau + h) * BRAKE_TIME) - braking(at_catch, (tau - h) * BRAKE_TIME)
        exact = braking(at_catch, tau * BRAKE_TIME)[3:9]
        assert np.allclose(step[0:6] / (2 * h * BRAKE_TIME), exact, atol=1e-5)


def test_the_jaws_reach_the_balls_diameter_the_lag_after_the_catch_time():
    plan = SimpleNamespace(t_catch=0.7)
    preshape, speed, lag = 0.081, 0.42, 0.004
    start = close_time(plan, preshape, BALL_DIAMETER, speed, lag)
    jaw = 0.5 * preshape - speed * (0.7 + lag - start)  # each jaw closes at the driver's speed
    assert abs(jaw - 0.5 * BALL_DIAMETER) < 1e-12
    assert close_time(None, preshape, BALL_DIAMETER, speed, lag) == float("inf")


def test_held_takes_the_squeezed_ball_and_refuses_an_empty_or_open_hand():
    assert _held(0.004, 0.055)  # measured: the jaws' 40 N squeeze the 65 mm ball to 55 mm
    assert not _held(0.004, 0.3 * BALL_DIAMETER)  # closed past it: not on the ball
    assert not _held(0.004, BALL_DIAMETER + 0.02)  # still open
    assert not _held(0.05, 0.06)  # on something, not the ball between the fingers


def test_the_summary_counts_the_oracles_reachable_throws():
    rows = [{"outcome": "caught", "reachable": True, "error_at_catch_mm": 3.0, "peak_contact_force_n": 80.0},
            {"outcome": "not reachable", "reachable": True, "error_at_catch_mm": None},
            {"outcome": "late", "reachable": False, "error_at_catch_mm": 40.0},
            {"status": "error", "reachable": None}]
    s = oracle.summary(rows)["catch"]
    assert s["catch_rate"] == 0.25 and s["reachable_rate"] == pytest.approx(2 / 3)
    assert s["caught_of_reachable"] == 0.5
    assert s["failures_by_reason"] == {"not reachable": 1, "late": 1, "error": 1}
    assert oracle.reachable(0) is True and oracle.reachable(96) is False  # the frozen file's verdicts
