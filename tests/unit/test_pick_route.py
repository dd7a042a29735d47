"""Issue 33: a pick whose way passes too near the arm's waist axis goes around it through a via
(``worlds.pick.route``); a way clear of the axis is planned as before."""

from pathlib import Path

import numpy as np

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick import route, ways
from ptint_drake.worlds.pick.tasks import VIA_PART, VIA_SLOT, pick_plan

MIRRORED = str(Path(__file__).resolve().parents[1] / "two_belt_pick_mirrored.yaml")


def _radius(world, x) -> float:
    return float(np.hypot(*(np.asarray(x)[:2] - world.axis)))


def test_a_way_past_the_waist_axis_gets_a_via_on_the_far_side_and_keeps_every_prescribed_time():
    """two_belt_pick_mirrored on rvm1_5dof: pick 1's approach from the tray (y = −0.24 m) to the
    block (+y) passes 113 mm from the axis, within 40 mm of the inner edge (≈ 85 mm)."""
    scenario = load_scenario(MIRRORED)
    arm = nominal_plant(scenario)
    world = ways.nominal(scenario, arm)
    straight, routed = pick_plan(scenario.pick), route.routed_plan(scenario, arm=arm)
    i = next(n for n, s in enumerate(straight.segments) if s.task == 1 and s.phase == "approach")
    assert route.too_near(world, ways.nominal_paths(world, straight)[i]) is not None
    via = [n for n, s in enumerate(routed.segments) if s.kind == VIA_PART]
    assert len(via) == 1
    j = via[0]
    assert (routed.segments[j].task, routed.segments[j + 1].phase) == (1, "approach")
    point = np.asarray(routed.segments[j].offset)
    edge = route.inner_edge(world, point)
    assert 0.07 < edge < 0.10  # the 5-joint arm's inner edge at z ≈ 0.18 m (wrist pitch at −90°)
    assert _radius(world, point) >= edge + route.INNER_MARGIN
    # the via and the approach share the approach's tf: its end and every later time stay put
    assert routed.schedule[j].start == straight.schedule[i].start
    assert np.isclose(routed.schedule[j + 1].end, straight.schedule[i].end)
    assert routed.grasp_times == straight.grasp_times and routed.close_times == straight.close_times
    assert routed.commands == straight.commands and np.isclose(routed.end, straight.end)
    # no way of the routed plan passes too near the edge any more
    for seg, path in zip(routed.segments, ways.nominal_paths(world, routed)):
        assert route.too_near(world, path) is None, seg


def test_a_way_clear_of_the_axis_is_planned_as_before():
    """The same scenario with the tray moved to the parts' side, and the bundled pick scenarios:
    no via around the base, the plan identical to the one without routing.  (The moved tray's
    second approach, rising from the tray's retreat point, grazes its own block at 1.9 mm: it gets
    a via above, ``obstacles`` — only the way around the base is asked of it here.)"""
    scenario = load_scenario(MIRRORED)
    scenario.pick.tray.center = [0.08, 0.24, 0.10]
    world = ways.nominal(scenario, nominal_plant(scenario))
    assert route.plan_vias(scenario, world) == ()
    assert {(v.task, v.phase) for v in route.routed_vias(scenario, world)} == {(1, "approach")}
    for s in [load_scenario(n) for n in ("conveyor_pick_place", "assembly_pick_place")]:
        routed, straight = route.routed_plan(s), pick_plan(s.pick)
        assert [p.phase for p in routed.segments] == [p.phase for p in straight.segments], s.name
        assert routed.segments == straight.segments and routed.commands == straight.commands
        assert routed.schedule.segments == straight.schedule.segments


def test_the_six_joint_arm_gets_no_via():
    """rvm1_6dof: the same ways are too near its inner edge too, but measured, both two-belt
    scenarios missed with the vias and place every part without them: its plan is the one without
    routing."""
    scenario = load_scenario(MIRRORED)
    scenario.robot.model, scenario.robot.initial_q_deg = "rvm1_6dof", [22.7, 46.5, 20.0, 0.0, 21.5, 0.0]
    assert route.routed_plan(scenario).segments == pick_plan(scenario.pick).segments


def test_a_carry_whose_wrist_would_turn_into_its_roll_limit_turns_the_other_way_round():
    """two_belt_pick_mirrored: the block grasped at tool yaw 155°, the carry would turn the tool to
    240° (the slot's 60° branch nearest it), rvm1_5dof's roll to −217° past its −180° limit; a via
    halfway along the carry turns it to 107.5°, so that the carry ends at 60°.  tests/two_belt_pick
    (its mirror image, the roll within its limits) gets no such via."""
    scenario = load_scenario(MIRRORED)
    plan = route.routed_plan(scenario)
    turns = [n for n, s in enumerate(plan.segments) if s.kind == VIA_SLOT]
    assert len(turns) == 1
    j = turns[0]
    assert (plan.segments[j].task, plan.segments[j + 1].phase) == (1, "carry")
    assert np.isclose(np.degrees(plan.segments[j].yaw), 107.5, atol=0.5)
    i = pick_plan(scenario.pick).segment_index(1, "carry")
    assert np.isclose(plan.schedule[j + 1].end, pick_plan(scenario.pick).schedule[i].end)
    original = load_scenario(str(Path(MIRRORED).with_name("two_belt_pick.yaml")))
    assert not [s for s in route.routed_plan(original).segments if s.kind == VIA_SLOT]
