"""The joint speeds a catch plan asks of the arm (issue 46, ``worlds/catch/speeds.py``): the
modelled motion's peak falls as the time allowed grows, rises with the matched fraction, and
the planner keeps every plan's peak within its share of the limits."""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.catch import thrower
from ptint_drake.worlds.catch.planner import MATCH_MARGIN, SPEED_SHARE, Planner, flight_states
from ptint_drake.worlds.catch.speeds import peak_ratio
from ptint_drake.worlds.catch.station import TIP, arm_plant

Q0 = np.radians([0.0, 30.0, 0.0, -95.0, 0.0, -95.0, 90.0])


def _catch(planner: Planner) -> tuple:
    """A catch point 0.15 m from the hand's start with a 4 m/s ball, and its posture's rotation."""
    x0 = planner.tip(Q0)[0]
    p, v = x0 + np.array([0.1, 0.08, -0.08]), np.array([-3.6, -0.3, -1.6])
    q = planner.ik(p, -v / np.linalg.norm(v), Q0)
    assert q is not None
    return p, v, planner.tip(q)[1]


def test_the_peak_falls_with_the_time_allowed_and_rises_with_the_matched_fraction():
    planner = Planner(arm_plant(), TIP, 0.5, 0.3, 0.2)
    p, v, R = _catch(planner)
    short, long = (peak_ratio(planner, Q0, 0.15, 0.15 + tf, p, v, R, 0.0, 0.2, 0.5) for tf in (0.4, 0.8))
    assert 1.7 < short / long < 2.3  # the approach's speeds scale with 1/tf
    matched = peak_ratio(planner, Q0, 0.15, 0.95, p, v, R, 0.3, 0.2, 0.5)
    assert matched > long + 0.1  # the matched velocity adds its own


def test_every_plan_keeps_its_modelled_joint_speeds_within_the_share():
    planner = Planner(arm_plant(), TIP, 0.5, 0.3, 0.2)
    start = planner.tip(Q0)[0]
    for seed in (0, 2, 58):
        th = thrower.throw(seed, start)
        sol = thrower.flight(np.array(th.launch), np.array(th.velocity), 1.0)
        truth = np.concatenate([sol(0.15)[:3], sol(0.15)[3:], thrower.GRAVITY])
        plan = planner.plan(truth, 0.15, Q0)
        assert plan is not None and plan.speed_ratio <= SPEED_SHARE
        v = flight_states(truth, [plan.t_catch - 0.15])[0, 3:6]
        again = peak_ratio(planner, Q0, 0.15, plan.t_catch, plan.point, v, plan.R, MATCH_MARGIN * plan.match,
                           0.2, 0.5, plan.q)
        assert abs(again - plan.speed_ratio) < 0.05


def test_the_match_bound_is_the_limits_own_and_above_what_the_planner_allows():
    """``Planner.match_bound``: the hand velocity it finds is the ball's direction at the full
    speed limits (a joint at its limit, none beyond), and no less than the planner's own cap on
    the matched velocity scaled from its share of the limits to all of them."""
    planner = Planner(arm_plant(), TIP, 0.5, 10.0, 0.2)  # match uncapped: matchable is the share's
    p, v, _ = _catch(planner)
    q = planner.ik(p, -v / np.linalg.norm(v), Q0)
    bound = planner.match_bound(q, v)
    assert 0.0 < bound < 1.0
    assert bound >= planner.matchable(q, v) / SPEED_SHARE - 1e-9
    slower = Planner(arm_plant(), TIP, 0.5, 10.0, 0.2)
    slower.v_max = 0.5 * planner.v_max
    assert abs(slower.match_bound(q, v) - 0.5 * bound) < 1e-6  # linear in the limits
