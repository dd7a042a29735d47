"""Issue 33: the arm's collision geometry, the floor, the collision report and the clearance check."""

import numpy as np
import pytest
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator

from ptint_drake.cli import main
from ptint_drake.simulation.scenario import load_scenario, parse_with_overrides, scenario_text
from ptint_drake.worlds.pick.collisions import collision_bodies
from ptint_drake.worlds.pick.metrics import pick_reasons
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.station import MakePickStation
from ptint_drake.worlds.pick.tasks import pick_plan

# rvm1_5dof with the fingertip centre at (0.30, 0, 0.09), pointing down: the fingers inside the belt
INTO_BELT_DEG = [0.0, 76.2, -5.9, 17.7, 0.0]


def _station(**robot):
    scenario = load_scenario("conveyor_pick_place")
    config = world_config(scenario)
    for key, value in robot.items():
        setattr(config, key, value)
    station = MakePickStation(config)
    context = station.diagram.CreateDefaultContext()
    station.diagram.GetInputPort("actuation").FixValue(context, np.zeros(5))
    station.diagram.GetInputPort("gripper_command").FixValue(context, [config.gripper.initial_opening])
    return station, context


def test_every_arm_link_and_finger_stem_has_collision_geometry():
    station, _ = _station()
    plant = station.plant
    for m in (station.arm, station.gripper):
        for b in plant.GetBodyIndices(m):
            body = plant.get_body(b)
            if body.name() != "tool":  # a frame-only link
                assert plant.GetCollisionGeometriesForBody(body), body.name()
    inspector = station.scene_graph.model_inspector()
    finger = plant.GetBodyByName("left_finger")
    names = {inspector.GetName(g) for g in plant.GetCollisionGeometriesForBody(finger)}
    assert any("stem" in n for n in names) and any("pad" in n for n in names), names


def _flags_after_a_step(station, context):
    Simulator(station.diagram, context).AdvanceTo(0.002)  # a discrete plant reports its last step's contacts
    return station.diagram.GetOutputPort("collisions").Eval(context).reshape(-1, 2)


def test_the_arm_in_a_belt_is_a_collision_with_that_belt_and_the_start_pose_is_not():
    flags = _flags_after_a_step(*_station())
    assert not np.any(flags), flags.tolist()
    station, context = _station(initial_q_deg=INTO_BELT_DEG)
    flags = _flags_after_a_step(station, context)
    touched = collision_bodies(station.obstacles, np.zeros(1), flags.reshape(1, -1), (0.0, 1.0), "part")
    assert touched == ["belt"], dict(zip(station.obstacles, flags.tolist()))
    reasons = pick_reasons([{"collision": True, "collision_with": touched, "t_grasp": 1.0,
                             "t_grasp_prescribed": 1.0, "grasped": True, "placed": True,
                             "grasp_confirmed": True, "held_at_place": True}])
    assert reasons == [(0, "collision with belt")]


def test_a_part_dropped_off_the_belts_lands_on_the_floor():
    station, context = _station()
    plant = station.plant
    pc = plant.GetMyMutableContextFromRoot(context)
    plant.SetFreeBodyPose(pc, station.parts[0], RigidTransform([-0.4, -0.4, 0.3]))  # behind the arm
    plant.SetVelocities(pc, station.arm, np.zeros(5))
    simulator = Simulator(station.diagram, context)
    simulator.AdvanceTo(0.6)
    z = station.parts[0].EvalPoseInWorld(pc).translation()[2]
    assert abs(z - 0.015) < 1e-3, z  # resting on z = 0, half its 30 mm height up


def test_a_start_pose_through_the_belt_is_rejected_before_the_run(tmp_path, capsys):
    code = main(["run", "conveyor_pick_place", "--quiet", "--no-replay", "--no-figures", "--out",
                 str(tmp_path / "o"), "--set", f"robot.initial_q_deg={INTO_BELT_DEG}"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "robot.initial_q_deg" in err and "belt" in err and len(err.splitlines()) == 1, err
    assert not (tmp_path / "o" / "metrics.json").exists()


def test_a_part_shorter_than_the_fingers_allow_at_its_centre_is_gripped_above_it():
    """A 16 mm part gripped at its centre would put the fingertips (10 mm past the fingertip centre)
    2 mm into its belt: the plan grips it 7 mm higher, so that they keep 5 mm above the belt at the
    grasp and above the tray at the place, and every target above the part or its slot rises by as
    much; a 30 mm part is gripped at its centre, as before."""
    for height, above in ((0.016, 0.007), (0.02, 0.005), (0.03, 0.0)):
        s = parse_with_overrides(scenario_text("conveyor_pick_place")[1],
                                 [f"pick.parts[0].size=[0.03,0.03,{height}]"])
        plan = pick_plan(s.pick)
        offsets = {seg.phase: seg.offset[2] for seg in plan.segments}
        task = s.pick.tasks[0]
        assert offsets["descend"] == pytest.approx(above) and offsets["place"] == pytest.approx(above)
        assert offsets["approach"] == pytest.approx(task.clearance + above)
        assert offsets["lift"] == pytest.approx(task.lift_height + above)
        assert offsets["retreat"] == pytest.approx(task.clearance + above)
        tips = height / 2 + above - 0.01  # the fingertips above the belt
        assert tips == pytest.approx(max(0.005, height / 2 - 0.01)), height


def test_a_part_too_short_to_hold_is_rejected_before_the_run(tmp_path, capsys):
    """An 8 mm part: with the fingertips 5 mm above its belt the pads would hold 3 mm of it."""
    code = main(["run", "conveyor_pick_place", "--quiet", "--no-replay", "--no-figures", "--out",
                 str(tmp_path / "o"), "--set", "pick.parts[0].size=[0.03,0.03,0.008]"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "pick.parts[0].size" in err and "too short to hold" in err, err
    assert len(err.splitlines()) == 1 and not (tmp_path / "o" / "metrics.json").exists()


def test_strict_hydroelastic_reports_the_arm_in_a_belt_instead_of_failing():
    """Strict hydroelastic contact needs a compliant side in every touching pair: the belts, tray
    and floor are compliant, the arm's links rigid."""
    station, context = _station(initial_q_deg=INTO_BELT_DEG, contact_model="hydroelastic")
    flags = _flags_after_a_step(station, context)
    touched = collision_bodies(station.obstacles, np.zeros(1), flags.reshape(1, -1), (0.0, 1.0), "part")
    assert touched == ["belt"], flags.tolist()


def test_a_retry_is_the_tasks_own_window():
    """A collision during task 1's first attempt belongs to pick 1 even after a retry moved its
    last approach later (seed 42 of the rgbd study reported it as pick 0's)."""
    from types import SimpleNamespace

    from ptint_drake.config.pick import (BeltConfig, PartConfig, PickConfig, PickTaskConfig, SlotConfig,
                                         TrayConfig)
    from ptint_drake.worlds.pick.collisions import pick_collisions
    from ptint_drake.worlds.pick.tasks import Replan, pick_plan

    pick = PickConfig(belts=[BeltConfig()], parts=[PartConfig(name="a"), PartConfig(name="b", offset=-0.1)],
                      tray=TrayConfig(slots=[SlotConfig(), SlotConfig(offset=[0.0, 0.05])]),
                      tasks=[PickTaskConfig(part="a", slot=0), PickTaskConfig(part="b", slot=1)])
    plan = pick_plan(pick)
    first = plan.schedule.segments[plan.segment_index(1, "approach")].start
    retry = first + 1.5  # task 1's descend found empty: a backoff and a second approach
    plan = pick_plan(pick, (Replan(), Replan((retry,))))
    assert plan.segment_index(1, "approach") != plan.segment_index(1, "approach", attempt=0)
    names = ["belt", "a", "b"]
    t = np.array([first + 0.2, first + 1.0])  # inside task 1's first attempt
    flags = np.zeros((2, 6))
    flags[:, 2 * 0 + 1] = 1.0  # the arm (not a finger) on the belt
    parts = [SimpleNamespace(name="a"), SimpleNamespace(name="b")]
    built = SimpleNamespace(plan=plan, station=SimpleNamespace(obstacles=names,
                                                               config=SimpleNamespace(parts=parts)))
    logs = {"collisions": (t, flags)}
    assert pick_collisions(built, logs, 0) == []
    assert pick_collisions(built, logs, 1) == ["belt"]


def test_a_line_part_placed_after_a_collision_is_warned_naming_the_bodies():
    from ptint_drake.worlds.pick.line.metrics import placed_collision_warnings  # noqa: PLC0415

    rows = [("a", True, 0), ("b", True, 1), ("c", False, 2), ("d", False, None)]
    line = {"parts": [{"part": p, "placed": placed, "task": task} for p, placed, task in rows]}
    picks = [{"collision": True, "collision_with": ["feed", "tray"]},
             {"collision": False, "collision_with": []}, {"collision": True, "collision_with": ["feed"]}]
    assert placed_collision_warnings({"line": line, "picks": picks}) == [
        "a: placed, but its task's arm or gripper touched feed, tray"]
    assert placed_collision_warnings({"picks": picks}) == []  # a task list: its pick's failure
