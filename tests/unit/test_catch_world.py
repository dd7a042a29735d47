"""The catch world (issue 46): its thrower draws the oracle's frozen throws, and the planner
refuses a ball that never comes near the hand (``not reachable``, decided before moving) and plans
a catch inside the workspace, after the sensing plus its minimum tf, for one that does."""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.catch import thrower
from ptint_drake.worlds.catch.planner import Planner
from ptint_drake.worlds.catch.station import TIP, arm_plant
from script_module import load_script

Q0 = np.radians([0.0, 30.0, 0.0, -95.0, 0.0, -95.0, 90.0])


def test_the_world_throws_what_the_oracle_throws():
    oracle = load_script("catch_oracle")
    start = oracle.Oracle().X0.translation()
    for seed in range(30):
        ours, frozen = thrower.throw(seed, start), oracle.throw(seed, start)
        assert np.allclose(ours.launch, frozen.launch, atol=1e-12)
        assert np.allclose(ours.velocity, frozen.velocity, atol=1e-9)
        assert ours.flight_time == frozen.flight_time


def test_the_planner_catches_in_reach_after_its_minimum_tf_and_refuses_out_of_reach():
    planner = Planner(arm_plant(), TIP, 0.75)
    start = planner.tip(Q0)[0]
    th = thrower.throw(2, start)
    sol = thrower.flight(np.array(th.launch), np.array(th.velocity), 1.0)
    truth = np.concatenate([sol(0.15)[:3], sol(0.15)[3:], thrower.GRAVITY])
    plan = planner.plan(truth, 0.15, Q0)
    assert plan is not None and plan.t_catch - 0.15 >= plan.tf_min
    assert np.linalg.norm(plan.point - sol(plan.t_catch)[:3]) < 0.03  # drag ignored: centimetres
    away = np.concatenate([[1.6, 0.0, 1.0], [1.4, 0.0, 2.0], thrower.GRAVITY])  # thrown away
    assert planner.plan(away, 0.15, Q0) is None
