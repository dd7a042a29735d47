"""Issue 44's CPU budget: a line's run ends once the line is done (``line.truth.LineTruth.run_end``)
— on the real station: not while a release is still to come, not while a released part rides its
belt or rests on a stopped one, not while a part moves or the arm's plan runs; done, the run ends
``SETTLE`` after the first stop that found it so, and goes back to the cap if it stops being done."""

import numpy as np
from pydrake.math import RigidTransform
from pydrake.systems.analysis import Simulator

from ptint_drake.config.line import SpeedStepConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.arrivals import Release, line_scenario
from ptint_drake.worlds.pick.line.truth import SETTLE, LineTruth
from ptint_drake.worlds.pick.run import build_pick
from ptint_drake.worlds.pick.scene import slot_pose

CAP = 14.5


def _setup(steps=()):
    scenario, _ = line_scenario(load_scenario("line_short"))
    scenario.pick.parts = scenario.pick.parts[:2]
    built = build_pick(scenario)
    releases = [Release(0, 0.1, "conveyor", "cube"), Release(1, 0.3, "conveyor", "cube")]
    truth = LineTruth(built.station, releases, list(steps))
    simulator = Simulator(built.diagram)
    context = simulator.get_mutable_context()
    built.station.start_running(built.station.plant.GetMyMutableContextFromRoot(context))
    truth.start(context)
    simulator.Initialize()
    return built, truth, simulator, context


def _advance(simulator, truth, context, times):
    for t in times:
        simulator.AdvanceTo(t)
        truth.at_stop(context, t)


def _to_slot(built, context, k, j):
    """Part k put in slot j of the tray, at rest (as a placed part is)."""
    station = built.station
    pc = station.plant.GetMyMutableContextFromRoot(context)
    X = slot_pose(station.config.tray, j)
    half = station.config.parts[k].size[2] / 2
    X = RigidTransform(X.rotation(), X.translation() + [0.0, 0.0, half])
    station.plant.SetFreeBodyPose(pc, station.parts[k], X)
    station.plant.SetVelocities(pc, station.parts[k].model_instance(), np.zeros(6))


def test_the_run_ends_only_when_the_line_is_done():
    built, truth, simulator, context = _setup()
    _advance(simulator, truth, context, [0.1, 0.2])
    # part 1 not released yet: not done, even with part 0 resting in the tray
    _to_slot(built, context, 0, 0)
    _advance(simulator, truth, context, [0.25])
    assert not truth.done(context, 0.25)
    _advance(simulator, truth, context, [0.3, 0.35])
    # both released; part 1 rides its belt: not done, the run keeps its cap
    assert truth.done(context, 0.35) is False
    assert truth.run_end(context, 0.35, False, 0.0, CAP) == CAP
    # both in the tray: done once they rest (the first stop after the drop sees them settle)
    _to_slot(built, context, 1, 2)
    _advance(simulator, truth, context, [0.5, 0.7])
    assert truth.done(context, 0.7)
    # the arm's plan still running, or a new task decided at the stop: the cap
    assert truth.run_end(context, 0.7, False, 0.9, CAP) == CAP
    assert truth.run_end(context, 0.7, True, 0.0, CAP) == CAP
    # done with the arm free: the end SETTLE after this stop, kept at the next stops while done
    assert truth.run_end(context, 0.7, False, 0.6, CAP) == 0.7 + SETTLE
    _advance(simulator, truth, context, [0.8])
    assert truth.run_end(context, 0.8, False, 0.6, CAP) == 0.7 + SETTLE
    # a part set moving (knocked): not done, back to the cap; done again later: a new end
    pc = built.station.plant.GetMyMutableContextFromRoot(context)
    built.station.plant.SetVelocities(pc, built.station.parts[0].model_instance(), [0, 0, 0, 0.05, 0, 0])
    assert truth.run_end(context, 0.8, False, 0.6, CAP) == CAP
    _to_slot(built, context, 0, 0)
    _advance(simulator, truth, context, [1.0, 1.2])
    assert truth.run_end(context, 1.2, False, 0.6, CAP) == 1.2 + SETTLE


def test_a_part_at_rest_on_a_stopped_belt_keeps_the_run_going():
    # the belt stopped at 0.4 s (a speed step to 0): its parts rest on it, still to be picked
    built, truth, simulator, context = _setup([SpeedStepConfig("conveyor", 0.4, 0.0)])
    _advance(simulator, truth, context, [0.1, 0.3, 0.4, 0.8, 1.5, 2.0])
    pc = built.station.plant.GetMyContextFromRoot(context)
    speeds = [np.linalg.norm(built.station.parts[k].EvalSpatialVelocityInWorld(pc).translational())
              for k in range(2)]
    assert max(speeds) < 1e-3  # at rest, on the stopped belt
    assert truth.on_belt(pc, 0) and truth.on_belt(pc, 1)
    assert not truth.done(context, 2.0)
    assert truth.run_end(context, 2.0, False, 0.0, CAP) == CAP
    # taken off the belt into the tray: done
    _to_slot(built, context, 0, 0)
    _to_slot(built, context, 1, 1)
    _advance(simulator, truth, context, [2.2, 2.4])
    assert truth.done(context, 2.4)
