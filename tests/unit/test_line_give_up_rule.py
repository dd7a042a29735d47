"""Issue 44: the line's give-up rule (``line.give_up``) — a kept task whose grasp its part's
reach window no longer allows is named so, the arm's hold goes up from where the tool is, and
the line's plan holds it (a fixed point from the moment of giving up) between the tasks."""

import numpy as np
import pytest

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.driver import LineDriver
from ptint_drake.worlds.pick.line.give_up import hold_of, unserved
from ptint_drake.worlds.pick.line.plan import IDLE_TF, Hold, line_plan
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.tasks import VIA_SLOT, Replan

WINDOW = (-0.10, 0.20)  # m along the belt
SLACK = 0.5  # s


def _track(s: float, speed: float) -> Track:
    return Track(0, "cube", "conveyor", (0.25, s, 0.15), s, (0.0, 1.0, 0.0), speed, (1.0, 0.0, 0.0),
                 0.03, 0.02)


def test_a_grasp_still_in_its_window_is_served():
    # at 0.1 m/s: 0.0 m at the approach's end (t = 1), 0.1 m at the grasp (t = 2), 0.05 m before
    # the window's end less the slack's ride
    assert unserved(_track(-0.1, 0.1), WINDOW, 2.0, 0.0, 1.0, SLACK) == ""


def test_a_belt_seen_faster_puts_the_grasp_past_reach():
    # the same grasp at 0.13 m/s: 0.16 m at the grasp, beyond 0.2 − 0.13 · 0.5 = 0.135 m
    why = unserved(_track(-0.1, 0.13), WINDOW, 2.0, 0.0, 1.0, SLACK)
    assert why.startswith("past reach at the grasp (2.00 s)")


def test_the_give_up_rule_asks_the_part_in_reach_at_the_lift_s_start_only():
    # 0.16 m at the grasp: past the keeping rule's 0.135 m (the scheduler's slack, 0.5 s), but a
    # dwell later (0.15 s: 0.18 m) still inside the window, where the lift starts above it
    dwell = PickTaskConfig().dwell
    assert unserved(_track(-0.1, 0.13), WINDOW, 2.0, 0.0, 1.0, dwell) == ""
    assert unserved(_track(-0.1, 0.17), WINDOW, 2.0, 0.0, 1.0, dwell) != ""  # 0.24 m: beyond


def test_a_belt_seen_slower_leaves_the_part_upstream_at_the_approach_end():
    why = unserved(_track(-0.3, 0.1), WINDOW, 2.0, 0.0, 1.0, SLACK)  # −0.2 m at t = 1
    assert why.startswith("upstream of reach at the approach's end (1.00 s)")


def test_the_hold_rises_to_the_lift_height_above_the_part_where_reachable():
    task = PickTaskConfig()
    part = np.array([0.25, 0.05, 0.15])
    hold = hold_of(3.0, np.array([0.24, 0.02, 0.17]), 0.4, part, lambda x: np.zeros(5))
    assert hold.position == pytest.approx((0.24, 0.02, 0.15 + task.lift_height))
    assert (hold.start, hold.tf, hold.beta, hold.yaw) == (3.0, task.retreat.tf, task.retreat.beta, 0.4)
    higher = hold_of(3.0, np.array([0.24, 0.02, 0.30]), 0.4, part, lambda x: np.zeros(5))
    assert higher.position[2] == pytest.approx(0.30)  # never lowered
    stays = hold_of(3.0, np.array([0.24, 0.02, 0.17]), 0.4, part, lambda x: None)
    assert stays.position == pytest.approx((0.24, 0.02, 0.17))  # no posture there: the tool's point


def test_the_line_plan_holds_a_given_up_task_s_hold_between_the_tasks():
    scenario = LineDriver(load_scenario("line_short")).scenario
    hold = Hold(4.0, 0.4, 0.75, (0.2, 0.1, 0.22), 0.3)
    alone = line_plan(scenario, (hold,))
    assert [s.start for s in alone.schedule.segments] == [0.0, 4.0] and alone.end == pytest.approx(4.4)
    held = alone.segments[1]
    assert (held.task, held.kind, held.offset, held.yaw) == (-1, VIA_SLOT, hold.position, hold.yaw)
    task = PickTaskConfig(part=scenario.pick.parts[0].name, slot=0, start=5.0)
    scenario.pick.tasks.append(task)
    plan = line_plan(scenario, (Replan(), hold))
    starts = [s.start for s in plan.schedule.segments]
    assert starts == sorted(starts) and starts[:3] == [0.0, 4.0, 5.0]
    assert plan.segments[1] == held and plan.segments[2].task == 0 and plan.schedule.segments[0].tf == IDLE_TF
    assert plan.end == line_plan(scenario, (Replan(),)).end  # the task's retreat ends after the hold
