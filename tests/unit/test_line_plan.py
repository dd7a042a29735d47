"""Issue 44: a line's plan — the idle segment at the tool's start pose before any task, and the
plan's model of the parts (``LineDriver.planning``) holding each tracked part where it was seen,
riding its belt at the known speed, and every unseen part far away."""

import numpy as np

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.camera import nominal_paths
from ptint_drake.worlds.pick.line.driver import FAR_UPSTREAM, LineDriver
from ptint_drake.worlds.pick.line.plan import IDLE_TF, home_pose, line_plan
from ptint_drake.worlds.pick.line.scheduler import Track


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
