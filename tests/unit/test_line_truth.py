"""Issue 44: the line's truth side (``worlds.pick.line.truth``) on the real station — a parked part
does not move and costs no contact, a released part rides its belt, the slab's reset does not
disturb it, a speed step changes the drive (the declared speed stays)."""

import numpy as np
from pydrake.systems.analysis import Simulator

from ptint_drake.config.line import SpeedStepConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.arrivals import Release, line_scenario
from ptint_drake.worlds.pick.line.truth import LineTruth, parking_pose
from ptint_drake.worlds.pick.run import build_pick


def _setup():
    scenario, _ = line_scenario(load_scenario("line_short"))
    scenario.pick.parts = scenario.pick.parts[:3]
    built = build_pick(scenario)
    releases = [Release(0, 0.1, "conveyor", "cube"), Release(1, 0.5, "conveyor", "cube"),
                Release(2, 9.0, "conveyor", "cube")]
    truth = LineTruth(built.station, releases, [SpeedStepConfig("conveyor", 0.6, 1.5)])
    simulator = Simulator(built.diagram)
    context = simulator.get_mutable_context()
    built.station.start_running(built.station.plant.GetMyMutableContextFromRoot(context))
    truth.start(context)
    return built, truth, simulator, context


def _state(built, context, k):
    plant = built.station.plant
    pc = plant.GetMyContextFromRoot(context)
    body = built.station.parts[k]
    return body.EvalPoseInWorld(pc).translation(), body.EvalSpatialVelocityInWorld(pc).translational()


def test_parked_released_reset_and_stepped():
    built, truth, simulator, context = _setup()
    simulator.Initialize()
    for t in (0.1, 0.2, 0.3, 0.5):
        simulator.AdvanceTo(t)
        truth.at_stop(context, t)
    p2, v2 = _state(built, context, 2)
    assert np.allclose(p2, parking_pose(2).translation(), atol=1e-12) and np.allclose(v2, 0.0)
    # released at 0.1 s: on the belt (top at 0.135 m), moving with it at 0.1 m/s
    p0, v0 = _state(built, context, 0)
    assert abs(p0[2] - (0.135 + 0.015)) < 1e-4 and abs(v0[1] - 0.1) < 1e-5
    assert abs(p0[1] - (-0.7 + 0.1 * 0.4)) < 2e-3  # 0.4 s on the belt
    # the slab was put back at its place at every stop, the part's velocity undisturbed
    joint = built.station.belts[0]
    pc = built.station.plant.GetMyContextFromRoot(context)
    assert joint.get_translation(pc) == 0.0
    simulator.AdvanceTo(0.55)
    assert abs(_state(built, context, 0)[1][1] - 0.1) < 1e-5
    # the speed step at 0.6 s: the drive at 0.15 m/s, the part follows; the declared speed unchanged
    simulator.AdvanceTo(0.6)
    truth.at_stop(context, 0.6)
    simulator.AdvanceTo(0.8)
    assert abs(joint.get_translation_rate(pc) - 0.15) < 1e-4
    assert abs(_state(built, context, 0)[1][1] - 0.15) < 1e-3
    assert built.station.config.belts[0].speed == 0.1
    # still parked after 0.8 s of simulation
    assert np.allclose(_state(built, context, 2)[0], parking_pose(2).translation(), atol=1e-12)
