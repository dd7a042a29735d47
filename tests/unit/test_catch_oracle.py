"""The catch world's reachability oracle (scripts/catch_oracle.py, issue 46): the frozen thrower
draws throws inside the issue's distribution whose dragged flight passes the aim point; the
decision says yes for a throw into the hand's reach, no (naming why) for one out of it, and the
minimum tf grows with how far the hand must go."""

from __future__ import annotations

import numpy as np
import pytest

from script_module import load_script


@pytest.fixture(scope="module")
def oracle():
    module = load_script("catch_oracle")
    return module, module.Oracle()


def test_throws_follow_the_distribution_and_pass_the_aim_point_with_drag(oracle):
    co, o = oracle
    start = o.X0.translation()
    throws = [co.throw(s, start) for s in range(40)]
    aims = np.array([t.aim for t in throws])
    for t in throws:
        p0, v0 = np.array(t.launch), np.array(t.velocity)
        assert 1.2 <= np.hypot(p0[0], p0[1]) <= 2.0 and 0.6 <= t.flight_time <= 0.9
        assert np.linalg.norm(np.array(t.aim) - start) <= 0.15
        true = co.flight(p0, v0, t.flight_time)(t.flight_time)[:3]
        assert np.linalg.norm(true - t.aim) < 1e-6
        free = p0 + v0 * t.flight_time + 0.5 * co.GRAVITY * t.flight_time ** 2
        assert np.linalg.norm(free - t.aim) > 0.005  # the drag moves the ball by 5 mm or more
    spread = max(np.linalg.norm(a - b) for a in aims for b in aims)
    assert spread >= 0.15
    assert co.throw(7, start) == co.throw(7, start)  # a function of its seed alone


def test_a_throw_into_reach_is_catchable_and_one_away_from_the_arm_is_not(oracle):
    co, o = oracle
    start = o.X0.translation()
    answer = o.decide(co.throw(2, start))
    assert answer["catchable"] and answer["t_catch"] - co.SENSING >= answer["tf_min"] > 0.0
    launch, away = np.array([1.6, 0.0, 1.0]), np.array([2.6, 0.0, 0.6])  # thrown away from the arm
    answer = o.decide(co.Throw(99, tuple(launch), tuple(co._shoot(launch, away, 0.7)), tuple(away), 0.7))
    assert not answer["catchable"] and answer["reason"] == "no catch point in reach"


def test_the_minimum_tf_grows_with_the_distance_to_the_catch_point(oracle):
    _, o = oracle
    start, R0 = o.X0.translation(), o.X0.rotation().matrix()
    tfs = [o.tf_min(start + d * np.array([0.0, 0.6, -0.8]), R0) for d in (0.0, 0.05, 0.1, 0.2)]
    assert tfs[0] == pytest.approx(0.0, abs=1e-9)
    assert all(a < b for a, b in zip(tfs, tfs[1:])), tfs
