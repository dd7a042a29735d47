"""Issue 44: a line's plan — the idle segment at the tool's start pose before any task, and the
plan's model of the parts (``LineDriver.planning``) holding each tracked part where it was seen,
riding its belt at the known speed, and every unseen part far away."""

from dataclasses import replace

import numpy as np
import pytest

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.camera import nominal_paths
from ptint_drake.worlds.pick.line.driver import FAR_UPSTREAM, LineDriver
from ptint_drake.worlds.pick.line.plan import IDLE_TF, Pin, home_pose, line_plan, pin_of
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.tasks import Replan, Via
from ptint_drake.worlds.pick.ways import nominal, segment_target


def test_the_idle_segment_holds_the_start_pose_until_the_first_task():
    scenario = load_scenario("line_short")
    plan = line_plan(scenario)
    (segment,) = plan.schedule.segments
    assert segment.start == 0.0 and segment.tf == IDLE_TF and plan.end == IDLE_TF
    (idle,) = plan.segments
    arm = nominal_plant(scenario)
    context = arm.CreateDefaultContext()
    arm.SetPositions(context, np.radians(scenario.robot.initial_q_deg))
    tool = arm.GetFrameByName("tool").CalcPoseInWorld(context).translation()
    assert idle.task == -1 and np.allclose(idle.offset, tool) and home_pose(scenario, arm)[0] == idle.offset
    assert plan.commands == ((0.0, scenario.pick.gripper.initial_opening),) and plan.grasp_times == ()


def test_the_plan_model_holds_the_tracked_parts_where_they_were_seen():
    driver = LineDriver(load_scenario("line_short"))
    t, speed = 7.3, 0.15  # the belt seen running 50 % faster than declared
    seen = Track(2, "cube", "conveyor", (0.262, -0.12, 0.15), -0.12, (0.0, 1.0, 0.0), speed,
                 (np.cos(0.3), np.sin(0.3), 0.0), 0.03, 0.0212)
    driver._believe([seen], t)
    planning = driver.planning()
    (p0, v), far = nominal_paths(planning.pick)[2], nominal_paths(planning.pick)[0]
    assert np.allclose(p0 + v * t, seen.position, atol=1e-9)  # there at the decision's time
    assert np.allclose(v, [0.0, speed, 0.0])
    assert abs(planning.pick.parts[2].yaw_deg - np.degrees(0.3)) < 1e-9
    assert far[0][1] < FAR_UPSTREAM / 2  # unseen: far upstream
    # the run's own scenario (the truth side's releases read it) is untouched
    assert driver.scenario.pick.parts[2].offset == -0.7 and driver.scenario.pick.belts[0].speed == 0.1


def test_a_pinned_approach_keeps_its_via_and_the_phases_after_the_grasp_follow_the_belief():
    """A task kept after a drift (``line.watch.keep``): its approach as the run follows it
    (``plan.Pin``: its via, or none, whatever the routing finds at the new belief), its lift —
    and the carry's way from there — where the part now is believed to be."""
    driver = LineDriver(load_scenario("line_short"))
    arm = nominal_plant(driver.scenario)
    t = 7.3
    seen = Track(2, "cube", "conveyor", (0.262, -0.12, 0.15), -0.12, (0.0, 1.0, 0.0), 0.1,
                 (1.0, 0.0, 0.0), 0.03, 0.0212)
    driver._believe([seen], t)
    part = driver.scenario.pick.parts[2].name
    driver.scenario.pick.tasks.append(PickTaskConfig(part=part, slot=0, start=t))
    before = line_plan(driver.planning(), (Replan(),), arm)
    driver._believe([replace(seen, speed=0.15)], t)  # the belt seen 50 % faster: the same part, now
    pin = pin_of(before, 0)
    after = line_plan(driver.planning(), (Replan(), pin), arm)
    approach = before.segment_index(0, "approach")
    assert after.segment_index(0, "approach") == approach
    for i in range(1, approach + 1):  # the idle segment's end on: the same segments, the same aims
        assert after.schedule.segments[i] == before.schedule.segments[i]
        assert after.segments[i] == before.segments[i]
    assert after.grasp_times == before.grasp_times
    lift = after.segment_index(0, "lift")
    start = after.schedule.segments[lift].start
    end = segment_target(nominal(driver.planning(), arm), after, lift, start)[0]
    lift_height = driver.scenario.pick.tasks[0].lift_height
    assert np.allclose(end, np.asarray(seen.position) + [0.0, 0.15 * (start - t), lift_height], atol=1e-9)
    # a pin is what the approach gets: a via where it names one, none where it names none
    via = Via(0, "approach", (0.2, 0.0, 0.25), 0.4)
    pinned = line_plan(driver.planning(), (Replan(), Pin(0, via)), arm)
    i = pinned.segment_index(0, "approach") - 1
    assert pinned.segments[i].phase == "via" and pinned.segments[i].offset == via.position
    task = driver.scenario.pick.tasks[0]
    assert pinned.schedule.segments[i].tf == pytest.approx(0.4 * task.approach.tf)
    assert pinned.schedule.segments[i].start == task.start and pinned.grasp_times == before.grasp_times
    bare = line_plan(driver.planning(), (Replan(), Pin(0, None)), arm)
    assert bare.segments[bare.segment_index(0, "approach") - 1].phase != "via"
    assert pin_of(pinned, 0) == Pin(0, Via(0, "approach", via.position, pytest.approx(0.4)))
