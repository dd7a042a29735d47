"""Issue 44: the line grips and places a part at a yaw chosen by its symmetry (``line.grip``) — a
30 mm cube across either pair of faces, a cylinder at any yaw — and the min-tf model, the task,
the plan and the targets the controller follows all take the yaw the decision chose."""

import math

import numpy as np
import pytest
from pydrake.math import RotationMatrix

from ptint_drake.config.pick import PartConfig, PickTaskConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.cycle import LineCycles
from ptint_drake.worlds.pick.line.grip import grips, puts
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.metrics import _place_angle
from ptint_drake.worlds.pick.phase_time import cycle_time
from ptint_drake.worlds.pick.targets import turned
from ptint_drake.worlds.pick.tasks import aimed_yaw, pick_plan

CUBE = PartConfig(name="c", shape="box", size=[0.03, 0.03, 0.03])
DISC = PartConfig(name="d", shape="cylinder", size=[0.03, 0.03])
BLOCK = PartConfig(name="b", shape="box", size=[0.04, 0.03, 0.03])
DEG = math.pi / 180.0


@pytest.fixture(scope="module")
def cycles():
    """The min-tf model of line_two_belts' station (the expanded scenario, as the run builds it)."""
    scenario, _ = line_scenario(load_scenario("line_two_belts"))
    return LineCycles(scenario)


def part(kind: str, yaw_deg: float, s: float = 0.0) -> Track:
    """A part of ``kind`` on line_two_belts' inner belt (x = 0.22 m, +y at 0.05 m/s), turned ``yaw_deg``."""
    axis = (math.cos(yaw_deg * DEG), math.sin(yaw_deg * DEG), 0.0)
    return Track(1, kind, "inner", (0.22, s, 0.15), s, (0.0, 1.0, 0.0), 0.05, axis, 0.03, 0.0212)


def test_a_cube_is_gripped_across_the_faces_nearest_the_tools_yaw_a_disc_at_the_tools_yaw():
    # a cube at 80° from the tool: 10° the other way (before: the part's x axis, an 80° turn)
    assert grips(CUBE, 80 * DEG, 0.0)[0] == pytest.approx(-10 * DEG)
    assert grips(CUBE, 80 * DEG, 0.0)[1] == pytest.approx(80 * DEG)  # the other pair of faces next
    assert grips(CUBE, 170 * DEG, 30 * DEG)[0] == pytest.approx(-10 * DEG)  # (40° from the tool; 80°: 50°)
    # a disc: no turn, whatever its x axis says (then ±45°, ±81°)
    assert grips(DISC, 70 * DEG, 0.3)[0] == pytest.approx(0.3)
    assert all(abs(g - 0.3) < 0.5 * math.pi for g in grips(DISC, 70 * DEG, 0.3))
    # a box with two different sides: its x axis modulo π, as before
    assert grips(BLOCK, 80 * DEG, 0.0) == [pytest.approx(80 * DEG)]


def test_a_cube_that_would_turn_a_near_quarter_to_its_slot_is_gripped_across_the_other_faces():
    """The controller may take a near-quarter turn either way round (``route.turn_ways``) and the
    model plans the slower: harsh line_assembly's first cube, at the slot's yaw 0, gripped at 90°
    from the start posture's 112.5° then carried to 0° or 180°; across the other faces (180°, a 67.5°
    approach) its carry turns nothing."""
    turned = grips(CUBE, 0.0, 112.5 * DEG, place_yaw=0.0)
    assert turned == [pytest.approx(math.pi), pytest.approx(0.5 * math.pi)]
    # no slot known: the nearer pair of faces first, as before
    assert grips(CUBE, 0.0, 112.5 * DEG, place_yaw=None)[0] == pytest.approx(0.5 * math.pi)
    # the other pair's approach would turn a near quarter itself: the order kept
    assert grips(CUBE, 0.0, 95 * DEG, place_yaw=0.0)[0] == pytest.approx(0.5 * math.pi)
    # the nearer grip's carry is no near quarter (a 30° part to the slot at 0°): the order kept
    assert grips(CUBE, 30 * DEG, 112.5 * DEG, place_yaw=0.0)[0] == pytest.approx(120 * DEG)


def test_the_chosen_grip_keeps_its_branch_while_the_estimate_moves():
    """The targets turn the part's estimated yaw by whole periods nearest the chosen yaw: an
    estimate that moves by less than half a period (45° for a cube) keeps the tool's branch."""
    grip = (-10 * DEG, 0.5 * math.pi)
    for estimate in (80.0, 110.0, 60.0, -10.0, 170.0):
        expected = (estimate - 90 * round((estimate + 10) / 90)) * DEG
        assert aimed_yaw(estimate * DEG, grip) == pytest.approx(expected)
        assert abs(aimed_yaw(estimate * DEG, grip) - grip[0]) <= 0.25 * math.pi + 1e-9
    assert aimed_yaw(1.2, (0.4, 0.0)) == 0.4  # a cylinder: the chosen yaw itself
    assert aimed_yaw(1.2, ()) == 1.2  # no chosen grip: the part's yaw (a task list's)
    tilted = RotationMatrix.MakeXRotation(0.1).multiply(RotationMatrix.MakeZRotation(80 * DEG)).matrix()
    R = turned(tilted.ravel(), grip).reshape(3, 3)
    seen = math.atan2(tilted[1, 0], tilted[0, 0])  # the tilted part's x axis, about 80°
    assert math.atan2(R[1, 0], R[0, 0]) == pytest.approx(seen - 0.5 * math.pi)
    assert R[2] == pytest.approx(tilted[2])  # turned about the vertical only: the tilt kept
    assert np.allclose(R @ R.T, np.eye(3))


def test_the_lead_takes_the_cube_turned_a_quarter_and_the_task_carries_it(cycles):
    start = np.array([0.11, 0.2, 0.15])
    cube = part("cube", 80.0, -0.1)
    found = cycles.found(cube, (-0.3, 0.3), start, 0.0)
    assert found[4] == pytest.approx(-10 * DEG)
    # the approach turning 10° is no longer than the one turning 80° (the old branch)
    up, ride = np.array([0.0, 0.0, 0.04]), np.array([0.0, 0.05, 0.0])
    cycles.model.last = found[0]
    old = cycles.model.min_tf(start, np.asarray(cube.position) + up, ride, 0.0, 0.75, (0.0, 80 * DEG))
    assert found[0] <= old + 1e-6
    grasp = 5.0 + math.ceil(cycles.lead(cube, (-0.3, 0.3), 5.0, start, 0.0) / 0.1) * 0.1
    cycle = cycles.phases(cube, (-0.3, 0.3), grasp, 5.0, start, 0.0, 3)
    assert cycle.yaws[0] == pytest.approx(-10 * DEG)
    assert cycle.yaws[1] == pytest.approx(0.0)  # the slot's own direction, nearest the grip
    task = cycles.task_of("cube_0", 3, grasp, 5.0, cycle)
    assert (task.grip_yaw, task.place_yaw) == cycle.yaws
    assert cycles.fits(cube, 5.0, grasp + 0.05, 5.0, start, 0.0, task.grip_yaw)


def test_a_dropped_grip_gives_the_next_one(cycles):
    start, cube = np.array([0.11, 0.2, 0.15]), part("cube", 80.0, -0.05)
    first = cycles.found(cube, (-0.3, 0.3), start, 0.0)[4]
    cycles.drop_grip(cube, (-0.3, 0.3), start, 0.0)  # (its cycle found no tf: ``driver``)
    assert cycles.found(cube, (-0.3, 0.3), start, 0.0)[4] == pytest.approx(80 * DEG)
    cycles.drop_grip(cube, (-0.3, 0.3), start, 0.0)  # every one dropped: all of them offered again
    assert cycles.grips(cube, 0.0)[0] == pytest.approx(first)
    cycles.choice.dropped.clear()


def test_a_turned_place_only_where_the_open_fingers_clear_the_trays_parts(cycles):
    """line_two_belts' tray: slots 50 mm apart in x, 40 mm in y.  A cube at slot 4 turned 90° from
    the slot (fingers along y) is offered while slot 1 (40 mm in −y) is empty, not once a part is
    there; a disc's place at its grip's yaw likewise; the slot's own direction, which clears it."""
    pick = cycles.scenario.pick
    place, neighbour = (place_point(pick, "slot", j, CUBE) for j in (4, 1))
    finger, own = (0.006, 0.02), [pytest.approx(0.0)]
    assert puts(CUBE, place, 0.0, 80 * DEG, [], finger, 0.012) == own + [pytest.approx(90 * DEG)]
    assert puts(CUBE, place, 0.0, 80 * DEG, [(neighbour, 0.0212)], finger, 0.012) == own
    assert puts(DISC, place, 0.0, 80 * DEG, [], finger, 0.012) == own + [pytest.approx(80 * DEG)]
    assert puts(DISC, place, 0.0, 80 * DEG, [(neighbour, 0.015)], finger, 0.012) == own
    assert puts(BLOCK, place, 0.0, 80 * DEG, [], finger, 0.012) == own


def test_a_cube_placed_a_quarter_turn_off_its_slot_is_placed_a_discs_yaw_is_not_judged():
    """The placement verdict (``metrics._place_angle``, unchanged: it folded by the symmetry
    before) judges a line's turned place right: the tilt only for a cylinder."""
    quarter = RotationMatrix.MakeZRotation(0.5 * math.pi).matrix()
    assert _place_angle(quarter, 0.0, "box", CUBE.size) == pytest.approx(0.0, abs=1e-9)
    assert _place_angle(quarter, 0.0, "box", BLOCK.size) == pytest.approx(90.0)
    assert _place_angle(RotationMatrix.MakeZRotation(1.3).matrix(), 0.0, "cylinder", DISC.size) == \
        pytest.approx(0.0, abs=1e-6)


def test_the_plan_aims_every_segment_of_a_task_at_its_chosen_yaws():
    scenario = load_scenario("conveyor_pick_place")
    pick = scenario.pick
    plain = pick_plan(pick)
    assert all(s.grip == () for s in plain.segments)  # a task list's plan: as before
    task = pick.tasks[0]
    pick.tasks[0] = PickTaskConfig(**{**task.__dict__, "grip_yaw": 0.3, "place_yaw": 1.2})
    plan = pick_plan(pick)
    mine = [s for s in plan.segments if s.task == 0]
    assert all(s.grip and s.grip[0] == 0.3 for s in mine)
    assert [s.yaw for s in mine if s.kind == "slot"] == [1.2, 1.2, 1.2]
    assert plain.schedule.starts == plan.schedule.starts


def test_the_cycle_at_the_default_yaws_is_the_old_one(cycles):
    """``cycle_time`` given the yaws the top-down task would take anyway is the same cycle."""
    x, ride, place = np.array([0.22, -0.1, 0.15]), np.array([0.0, 0.05, 0.0]), np.array([0.11, 0.2, 0.115])
    start = place + [0.0, 0.0, 0.04]
    old = cycle_time(cycles.model, x, ride, place, 0.0, 0.6, 0.1, None, start, 0.0)
    new = cycle_time(cycles.model, x, ride, place, 0.0, 0.6, 0.1, None, start, 0.0, grip=0.6, put=0.0)
    assert new.phases == old.phases and old.yaws == (0.6, 0.0)


def test_the_targets_aim_the_tool_at_the_chosen_grip_while_the_part_is_followed():
    """``PickTargets`` of a task with ``grip_yaw`` −10° and a cube (``aimed_yaw``): at the approach
    the target rotation is the part's (80°) turned a quarter to −10°; the slot's place at
    ``place_yaw``; a disc's target stays at the chosen yaw however it is turned."""
    from ptint_drake.worlds.pick.config import BeltConfig, SlotConfig, TrayConfig
    from ptint_drake.worlds.pick.targets import PickTargets
    from ptint_drake.worlds.pick.tasks import PickConfig

    def aim(shape: str, size: list, part_yaw: float) -> tuple:  # (approach, place) yaws
        pick = PickConfig(belts=[BeltConfig()], parts=[PartConfig(name="a", shape=shape, size=size)],
                          tray=TrayConfig(slots=[SlotConfig()]),
                          tasks=[PickTaskConfig(part="a", slot=0, grip_yaw=-10 * DEG, place_yaw=90 * DEG)])
        plan = pick_plan(pick)
        system = PickTargets(plan, 1, [np.array([0.1, 0.2, 0.115]) if s.kind == "slot" else None
                                       for s in plan.segments])
        context = system.CreateDefaultContext()
        R = RotationMatrix.MakeZRotation(part_yaw).matrix()
        system.GetInputPort("part_0_pose").FixValue(context, np.r_[0.3, -0.05, 0.15, 0.0, 0.1, 0.0, 0, 0, 0])
        system.GetInputPort("part_0_rotation").FixValue(context, np.r_[R.ravel(), np.zeros(6)])
        context.SetTime(0.5)
        approach = system.GetOutputPort("target_rotation").Eval(context)[0:9].reshape(3, 3)
        context.SetTime(plan.schedule.segments[4].start + 0.1)
        place = system.GetOutputPort("target_rotation").Eval(context)[0:9].reshape(3, 3)
        return math.atan2(approach[1, 0], approach[0, 0]), math.atan2(place[1, 0], place[0, 0])

    grip, put = aim("box", [0.03, 0.03, 0.03], 80 * DEG)
    assert grip == pytest.approx(-10 * DEG) and put == pytest.approx(90 * DEG)
    assert aim("box", [0.03, 0.03, 0.03], 60 * DEG)[0] == pytest.approx(-30 * DEG)  # (the estimate moved)
    assert aim("cylinder", [0.03, 0.03], 1.0)[0] == pytest.approx(-10 * DEG)
    assert aim("cylinder", [0.03, 0.03], -2.0)[0] == pytest.approx(-10 * DEG)


def test_from_the_trays_near_column_the_chosen_grip_fits_where_the_parts_axis_has_no_posture(cycles):
    """Session 46's case: from above the tray's near column (x = 0.06 m) with the tool at yaw 0, a
    part at yaw −1.5 rad on the inner belt at y = 0.2 m — its x axis's branch (the grip before) has
    no top-down posture all along the approach (the wrist's roll at its limit: the lead waited);
    the cube's quarter-turned branch (4°) and the disc at the tool's yaw fit with no wait."""
    from ptint_drake.worlds.pick.phase_time import NoTfFits

    start, up, ride = np.array([0.06, 0.16, 0.155]), np.array([0.0, 0.0, 0.04]), np.array([0.0, 0.05, 0.0])
    for k, kind in enumerate(("cube", "disc")):
        track = Track(40 + k, kind, "inner", (0.22, 0.2, 0.15), 0.2, (0.0, 1.0, 0.0), 0.05,
                      (math.cos(-1.5), math.sin(-1.5), 0.0), 0.03, 0.0212)
        approach, _, wait, _, grip = cycles.found(track, (-0.3, 0.3), start, 0.0)
        assert wait == 0.0 and abs(grip) < 0.1, (kind, grip)
        cycles.model.last = approach
        with pytest.raises(NoTfFits):
            cycles.model.min_tf(start, np.asarray(track.position) + up, ride, 0.0, 0.75, (0.0, -1.5))
