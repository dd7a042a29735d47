"""Issue 44: ``ptint robust`` on a line (``worlds.pick.line.robust``) — the draws go to the truth
side only: the belt runs at the drawn speed while the controller side, with no encoder, predicts
with the declared one; each pool part gets its drawn mass and friction while the catalog (the
controller side's object model) keeps its kind's; a task-list pick draws what it drew before."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from ptint_drake.config.errors import ScenarioError
from ptint_drake.simulation.scenario import load_scenario, scenario_text
from ptint_drake.studies import robust
from ptint_drake.worlds.pick.line.arrivals import close_delay, line_scenario
from ptint_drake.worlds.pick.line.truth import LineTruth
from ptint_drake.worlds.pick.line.view import LineView
from ptint_drake.worlds.pick.run import build_pick

NAME, TEXT = scenario_text("line_assembly")


def test_a_line_sample_draws_per_pool_part_in_the_documented_order():
    declared = load_scenario("line_assembly")
    for seed in (0, 3):
        scenario, params = robust.sample_scenario(TEXT, NAME, seed, robust.RANGES)
        rng = np.random.default_rng(seed)
        u = robust.Draws(rng, robust.RANGES)
        assert params["mass_scale"] == scenario.plant.mass_scale == u("mass")
        truth = scenario.pick.line.truth
        for k in range(3):  # the three parts' mass and friction, then the three belts' speeds
            assert (truth.mass[k], truth.friction[k]) == (u("part_mass"), u("part_friction"))
        factors = [u("belt_speed") for _ in range(3)]
        assert truth.close_delay == [u("close_jitter") for _ in range(3)]
        assert truth.lateral == [u("part_lateral") for _ in range(3)]
        # the drive's speed from t = 0, the truth's; the declared speed and the catalog untouched
        steps = scenario.pick.line.speed_steps
        assert [(s.belt, s.t, s.factor) for s in steps] == [
            (b.name, 0.0, f) for b, f in zip(declared.pick.belts, factors)]
        assert params["belt_speed"] == pytest.approx([0.1 * f for f in factors], abs=1e-15)
        assert [b.speed for b in scenario.pick.belts] == [b.speed for b in declared.pick.belts]
        assert params["belt_encoder"] == [False] * 3
        assert scenario.pick.line.catalog[0].mass == declared.pick.line.catalog[0].mass
        expanded, _ = line_scenario(scenario)
        assert [p.mass for p in expanded.pick.parts] == truth.mass
        assert [p.friction for p in expanded.pick.parts] == truth.friction
        assert [close_delay(truth, n) for n in range(3)] == truth.close_delay


def test_the_truth_runs_the_drawn_speed_and_the_controller_side_predicts_the_declared():
    """Seed 0: conveyor1 drawn at 1.59 × its 0.1 m/s.  After its part's release the slab and the
    part move at the drawn speed; the track the scheduler reads moves at the declared 0.1 m/s (no
    encoder: the known speed), while the sensor's own velocity of the part shows the truth."""
    scenario, params = robust.sample_scenario(TEXT, NAME, 0, robust.RANGES)
    expanded, releases = line_scenario(scenario)
    built = build_pick(expanded)
    truth = LineTruth(built.station, releases, scenario.pick.line.speed_steps)
    view = LineView(expanded)
    view.bind(built)
    simulator = Simulator(built.diagram)
    context = simulator.get_mutable_context()
    station = built.station
    station.start_running(station.plant.GetMyMutableContextFromRoot(context))
    truth.start(context)
    simulator.Initialize()
    for t in (0.1, 0.3):
        simulator.AdvanceTo(t)
        truth.at_stop(context, t)
    drawn = params["belt_speed"][0]
    assert abs(drawn / 0.1 - 1.0) > 0.3
    pc = station.plant.GetMyContextFromRoot(context)
    assert station.belts[0].get_translation_rate(pc) == pytest.approx(drawn, rel=1e-3)
    (track,) = view.tracks(context, 0.3)
    assert track.belt == "conveyor1" and track.speed == 0.1
    assert track.measured == pytest.approx(drawn, rel=1e-2)
    assert station.config.belts[0].speed == 0.1


def test_a_task_list_pick_draws_as_before():
    """The harsh ranges on assembly_pick_place: link masses, each part's mass and friction, each
    belt's speed, each task's close jitter, each part's lateral offset, in that order."""
    name, text = scenario_text("assembly_pick_place")
    base = load_scenario("assembly_pick_place")
    scenario, params = robust.sample_scenario(text, name, 5, robust.RANGES)
    u = robust.Draws(np.random.default_rng(5), robust.RANGES)
    assert params["mass_scale"] == u("mass")
    assert [(p.mass, p.friction) for p in scenario.pick.parts] == [(u("part_mass"), u("part_friction"))
                                                                   for _ in range(3)]
    assert [b.speed for b in scenario.pick.belts] == [b.speed * u("belt_speed") for b in base.pick.belts]
    assert [t.close_delay for t in scenario.pick.tasks] == [u("close_jitter") for _ in range(3)]
    assert [p.lateral for p in scenario.pick.parts] == [float(np.clip(u("part_lateral"), -0.02, 0.02))
                                                        for _ in range(3)]
    assert scenario.pick.line is None and "belt_encoder" not in params


def test_a_truth_list_of_another_length_than_the_pool_is_named():
    scenario = load_scenario("line_assembly")
    scenario.pick.line.truth.mass = [0.2, 0.3]
    with pytest.raises(ScenarioError, match=r"pick\.line\.truth\.mass: 2 values for the pool's 3 parts"):
        line_scenario(scenario)
