"""Issue 44: a line seen by the camera — what its controller side reads of the perception's tracks
(``worlds.pick.line.seen.LineSeenParts``, its tracker state input fixed): a task's slot reads the
track it is aimed at, moved along its belt at the filter's speed along it, at the class's height,
turned by the mean of its fitted yaws (unwrapped by the class's symmetry); an unaimed slot reads
nothing; a track that ended keeps its last row, extrapolated; the plan's model holds tracked
parts at their tasks' slots or at free ones (``view.LineView.slots_of``); and the timeline marks
a line part seen when the line saw it; an identity switch is in the verdict; the line's camera
tells a cube from a disc of the same width."""

import math
from dataclasses import replace

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from static_scene import StaticScene

from ptint_drake.config.measurement import BeltRegionConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.systems.perception.tracks import Detection, Tracker
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.metrics import line_reasons
from ptint_drake.worlds.pick.line.seen import LineSeenParts, line_perception
from ptint_drake.worlds.pick.line.view import LineView
from ptint_drake.worlds.pick.timeline import part_timelines

PERIOD = 1.0 / 30.0
CUBE, DISC = 0, 1  # line_two_belts' catalog
OUTER = 0  # its belts: outer (x = 0.30 m), inner (0.22 m), both 0.1 m/s along +y, top at 0.135 m


def _frames(tracker: Tracker, count: int, yaws, start=(0.30, -0.40), kind=CUBE) -> list:
    """``count`` frames of one part riding the outer belt at 0.1 m/s (yaw per frame from ``yaws``);
    per frame the tracker's state vector after it."""
    states = []
    for k in range(count):
        t = k * PERIOD
        p = np.array([start[0], start[1] + 0.1 * t, 0.15])
        tracker.step(t, [Detection(p, yaws[k % len(yaws)], kind, OUTER)])
        states.append(tracker.state_vector())
    return states


def _system(slots: int = 4):
    config = line_perception(load_scenario("line_two_belts_rgbd"))
    config.tracking.visible = None  # (the test's part need not be in the camera's view)
    return config, LineSeenParts(config, slots)


def test_an_aimed_slot_reads_its_track_and_keeps_it_when_the_track_ends():
    config, system = _system()
    tracker = Tracker(config.tracking)
    # a cube's fits at ±44°: modulo 90° the same yaw, unwrapped about 45°, their mean 45°
    states = _frames(tracker, 12, [math.radians(44.0), math.radians(-44.0)])
    (track,) = tracker.tracks
    system.aim({2: track.id})
    context = system.CreateDefaultContext()
    port = system.get_input_port()
    simulator = Simulator(system, context)
    for k, state in enumerate(states):  # each frame's state, read at the next frame's time
        port.FixValue(context, state)
        simulator.AdvanceTo((k + 1) * PERIOD - 1e-6)
    t = context.get_time()
    pose = system.GetOutputPort("part_2_pose").Eval(context)
    # the filter's centre (frame 11 at y = -0.4 + 0.1 × 11/30) moved on at 0.1 m/s, on the belt's top
    assert pose[0:3] == pytest.approx([0.30, -0.40 + 0.1 * t, 0.135 + 0.015], abs=1e-3)
    assert pose[3:6] == pytest.approx([0.0, 0.1, 0.0], abs=2e-3) and pose[4] > 0.0
    R = system.GetOutputPort("part_2_rotation").Eval(context)[0:9].reshape(3, 3)
    assert abs(abs(math.degrees(math.atan2(R[1, 0], R[0, 0]))) - 45.0) < 0.6
    assert not np.any(system.GetOutputPort("part_0_pose").Eval(context))  # no task aims slot 0
    # the track ends (an empty tracker): the slot keeps its last row, extrapolated
    port.FixValue(context, Tracker(config.tracking).state_vector())
    simulator.AdvanceTo(t + 1.0)
    later = system.GetOutputPort("part_2_pose").Eval(context)
    assert later[1] - pose[1] == pytest.approx(0.1 * (context.get_time() - t), abs=2e-3)


def test_a_disc_has_no_yaw_and_sits_at_its_own_height():
    config, system = _system()
    tracker = Tracker(config.tracking)
    states = _frames(tracker, 6, [0.7, -1.3], kind=DISC)
    (track,) = tracker.tracks
    system.aim({0: track.id})
    context = system.CreateDefaultContext()
    simulator = Simulator(system, context)
    for k, state in enumerate(states):
        system.get_input_port().FixValue(context, state)
        simulator.AdvanceTo((k + 1) * PERIOD - 1e-6)
    pose = system.GetOutputPort("part_0_pose").Eval(context)
    assert pose[2] == pytest.approx(0.135 + 0.015, abs=1e-9)  # a 30 mm high disc
    R = system.GetOutputPort("part_0_rotation").Eval(context)[0:9].reshape(3, 3)
    assert R == pytest.approx(np.eye(3))


def test_the_plan_holds_aimed_tracks_at_their_tasks_slots_and_others_at_free_ones():
    scenario, _ = line_scenario(load_scenario("line_two_belts_rgbd"))
    view = LineView(scenario)
    n = len(scenario.pick.parts)
    view.aim(0, 7)  # a task picks pool part 0: track 7
    slots = view.slots_of([7, 3, 9])
    assert slots[7] == 0
    assert sorted([slots[3], slots[9]]) == [n - 2, n - 1]  # free slots, from the last one down
    pose = LineView(load_scenario("line_two_belts"))  # the pose sensor: its ids are the slots
    assert pose.slots_of([4, 1]) == {4: 4, 1: 1}


def test_a_line_part_is_on_the_timeline_when_the_line_saw_it():
    # the line's own ``seen`` (the camera's first fit; the pose line's release), not 0 for every part
    metrics = {"picks": [], "segments": [], "line": {"parts": [{"seen": 9.87}, {"seen": None}]}}
    for camera in (True, False):
        lines = part_timelines(["cube_0", "disc_1"], {}, metrics, camera)
        assert [line.seen for line in lines] == [9.87, None]


def test_a_line_part_lost_with_no_task_is_failed_on_the_timeline_and_a_part_never_released_absent():
    # cube_0 given up or never taken (``line.metrics``: its reason and when, no task); the pool's
    # third part never released (``arrivals.idle_part``): no row, no line on the timeline
    rows = [{"seen": 1.5, "task": None, "reason": "not reachable in time", "failed_at": 13.9},
            {"seen": 2.0, "task": None, "reason": None}]
    metrics = {"picks": [], "segments": [], "reason_codes": [], "line": {"parts": rows}}
    lines = part_timelines(["cube_0", "cube_1", "cube_2"], {}, metrics, False)
    assert [line.name for line in lines] == ["cube_0", "cube_1"]
    assert lines[0].failed == ["not reachable in time"] and lines[0].ended == 13.9
    assert lines[1].failed == [] and lines[1].ended is None


def test_a_slot_aimed_between_frames_reads_its_track_at_once():
    config, system = _system()
    tracker = Tracker(config.tracking)
    states = _frames(tracker, 5, [0.3])
    (track,) = tracker.tracks
    system.aim({1: track.id})
    context = system.CreateDefaultContext()  # no frame copied yet: the rows are empty
    system.get_input_port().FixValue(context, states[-1])
    context.SetTime(4 * PERIOD)
    pose = system.GetOutputPort("part_1_pose").Eval(context)
    assert pose[0:3] == pytest.approx([0.30, -0.40 + 0.1 * 4 * PERIOD, 0.15], abs=1e-3)
    R = system.GetOutputPort("part_1_rotation").Eval(context)[0:9].reshape(3, 3)
    assert math.atan2(R[1, 0], R[0, 0]) == pytest.approx(0.3, abs=1e-6)


def test_an_identity_switch_is_in_the_verdict():
    part = {"part": "cube_0", "entered": True, "placed": True, "reason": None}
    assert line_reasons({"parts": [part], "idsw": 0}) == []
    (reason,) = line_reasons({"parts": [part], "idsw": 2})
    assert reason.code == "identity switch" and "2 identity switches" in reason.message


@pytest.mark.parametrize("kind", [CUBE, DISC])
def test_the_line_camera_tells_a_cube_from_a_disc_of_one_width(kind):
    # rendered by line_two_belts_rgbd's camera: a 30 mm cube at yaw 0 (its square top and a disc's
    # round one have the same smallest rectangle; by the size alone 5 of 16 frames called it a disc)
    camera = load_scenario("line_two_belts_rgbd").measurement.camera
    config = line_perception(load_scenario("line_two_belts_rgbd"))
    shape, size = config.catalog[kind]
    belts = [BeltRegionConfig(center=list(b.center), direction=list(b.direction), length=float(b.length),
                              width=float(b.width)) for b in config.belts]
    camera = replace(camera, part_shape=shape, part_size=size, belts=belts)
    for y in (-0.25, -0.1, 0.05):
        scene = StaticScene(camera, [([0.30, y, 0.15], 0.0)], check_above=True)
        scene.estimator._c.catalog = config.catalog  # the line's catalog: cube, disc
        kinds = [[f.kind for f in scene.fits(k / 30.0)[0] if f.ok] for k in range(6)]
        assert kinds == [[kind]] * 6, (y, kinds)
