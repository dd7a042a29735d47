"""Issue 20: a pick task as prescribed-time segments, and what each segment aims at."""

import numpy as np
import pytest

from ptint_drake.simulation.validation import ScenarioError
from ptint_drake.worlds.pick.config import BeltConfig, PartConfig, SlotConfig, TrayConfig
from ptint_drake.worlds.pick.targets import GripperSequence, PickTargets
from ptint_drake.worlds.pick.tasks import (PHASES, MoveConfig, PickConfig, PickTaskConfig, check_tasks,
                                           pick_plan)


def _pick(**task) -> PickConfig:
    return PickConfig(belts=[BeltConfig()], parts=[PartConfig(name="a"), PartConfig(name="b", offset=-0.1)],
                      tray=TrayConfig(slots=[SlotConfig(), SlotConfig(offset=[0.0, 0.05], yaw_deg=90.0)]),
                      tasks=[PickTaskConfig(**{"part": "b", "slot": 1, **task}),
                             PickTaskConfig(part="a", slot=0)])


def test_plan_times_and_the_close_before_the_prescribed_grasp():
    pick = _pick(approach=MoveConfig(1.0), descend=MoveConfig(0.5, 0.6))
    plan = pick_plan(pick)
    segs = plan.schedule.segments
    assert [s.phase for s in plan.segments] == list(PHASES) * 2
    assert segs[0].start == 0.0 and segs[1].start == 1.0 and segs[1].beta == 0.6
    assert plan.grasp_times[0] == pytest.approx(1.5)
    # the fingers close (opening − width)/2 at their speed before the grasp: contact at tf
    assert plan.close_times[0] == pytest.approx(1.5 - 0.5 * 0.012 / 0.05)
    assert segs[2].start == pytest.approx(1.5 + 0.15)  # lift after the dwell
    assert segs[5].start == pytest.approx(segs[4].end + 0.15)  # retreat after the fingers opened
    assert segs[6].start == pytest.approx(segs[5].end)  # the next task right after
    first = plan.segments[0]
    assert first.kind == "part" and first.index == 1 and first.offset[2] == 0.04
    assert plan.segments[4].kind == "slot" and plan.segments[4].yaw == pytest.approx(np.pi / 2)
    sequence = GripperSequence(plan.commands)
    assert sequence.opening(0.5) == pytest.approx(0.042) and sequence.opening(plan.close_times[0]) == 0.0
    assert sequence.opening(segs[4].end) == pytest.approx(0.042)


@pytest.mark.parametrize("change, field", [
    (dict(part="c"), "pick.tasks[0].part"), (dict(slot=2), "pick.tasks[0].slot"),
    (dict(lift=MoveConfig(0.0)), "pick.tasks[0].lift.tf"),
    (dict(carry=MoveConfig(1.0, 1.0)), "pick.tasks[0].carry.beta"),
    (dict(dwell=0.0), "pick.tasks[0].dwell"), (dict(margin=0.05), "pick.tasks[0].margin"),
])
def test_bad_tasks_name_the_field(change, field):
    with pytest.raises(ScenarioError, match=field.replace("[", r"\[").replace("]", r"\]")):
        check_tasks(_pick(**change))


def test_targets_follow_the_simulated_part_then_latch_and_place():
    plan = pick_plan(_pick())
    places = [None if s.kind != "slot" else np.array([0.1, 0.2, 0.115]) for s in plan.segments]
    system = PickTargets(plan, 2, places)
    context = system.CreateDefaultContext()
    pose = np.r_[0.3, -0.05, 0.15, 0.0, 0.1, 0.0, 0.0, 0.0, 3.0]  # ẍ of a contact chatter
    R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    system.GetInputPort("part_0_pose").FixValue(context, np.zeros(9))
    system.GetInputPort("part_0_rotation").FixValue(context, np.r_[np.eye(3).ravel(), np.zeros(6)])
    system.GetInputPort("part_1_pose").FixValue(context, pose)
    system.GetInputPort("part_1_rotation").FixValue(context, np.r_[R.ravel(), 0.0, 0.0, 0.2, 0.0, 0.0, 9.0])
    context.SetTime(0.5)  # approach: clearance above the moving part, its velocity, no acceleration
    target = system.GetOutputPort("target").Eval(context)
    np.testing.assert_allclose(target, [0.3, -0.05, 0.19, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0])
    rotation = system.GetOutputPort("target_rotation").Eval(context)
    np.testing.assert_allclose(rotation, np.r_[R.ravel(), 0.0, 0.0, 0.2, 0.0, 0.0, 0.0])
    segs = plan.schedule.segments
    context.SetTime(segs[4].start + 0.1)  # place: the slot's pose, turned to its yaw, at rest
    np.testing.assert_allclose(system.GetOutputPort("target").Eval(context), [0.1, 0.2, 0.115] + [0.0] * 6)
    rotation = system.GetOutputPort("target_rotation").Eval(context)
    np.testing.assert_allclose(rotation[0:9], R.ravel(), atol=1e-12)


def test_robust_samples_a_pick_scenario_within_its_ranges():
    from ptint_drake.simulation.scenario import scenario_text
    from ptint_drake.studies.robust import RANGES, sample_scenario
    from ptint_drake.worlds.pick.studies import robust_summary

    _, text = scenario_text("conveyor_pick_place")
    for seed in range(5):
        scenario, params = sample_scenario(text, "p", seed)
        assert 0.7 <= scenario.plant.mass_scale <= 1.5 and scenario.plant.payload_kg == 0.0
        part, belt = scenario.pick.parts[0], scenario.pick.belts[0]
        assert RANGES["part_mass"][0] <= part.mass <= RANGES["part_mass"][1]
        assert RANGES["part_friction"][0] <= part.friction <= RANGES["part_friction"][1]
        lo, hi = RANGES["belt_speed"]
        assert 0.1 * lo <= belt.speed <= 0.1 * hi and params["belt_speed"] == [belt.speed]
    two = {"part_mass": [0.1, 0.1]}
    rows = [{"params": two, "picks": [{"placed": True}, {"placed": False}], "reasons": ["pick 1: dropped"]},
            {"params": two, "error": "boom", "ok": False}]
    summary = robust_summary(rows)
    assert summary["pick_success_rate"] == 0.25
    assert summary["failures_by_reason"] == {"dropped": 1, "error: boom": 1}


def test_collisions_are_one_reason_with_the_bodies_counted_beneath():
    """failures_by_reason keys a collision by its kind, whatever bodies it touched (stable keys);
    collisions_by_body counts how many collisions touched each body."""
    from ptint_drake.worlds.pick.studies import robust_summary  # noqa: PLC0415

    one = {"part_mass": [0.1]}
    rows = [{"params": one, "picks": [{"placed": False}],
             "reasons": ["pick 0: collision with conveyor2, tray, floor, part2", "pick 0: dropped"]},
            {"params": one, "picks": [{"placed": False}], "reasons": ["pick 0: collision with tray"]},
            {"params": one, "picks": [{"placed": False}], "reasons": ["pick 0: collision"]}]
    summary = robust_summary(rows)
    assert summary["failures_by_reason"] == {"collision": 3, "dropped": 1}
    assert summary["collisions_by_body"] == {"tray": 2, "conveyor2": 1, "floor": 1, "part2": 1}
