"""Issue 44: an approach that would sweep through a part is re-routed above it and the part placed
(tests/low_tray_pick.yaml: the tray lower than the belt, the next box in line; ``obstacles``)."""

from pathlib import Path

import pytest

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick import obstacles, route, ways
from ptint_drake.worlds.pick.tasks import pick_plan

SCENARIO = str(Path(__file__).resolve().parents[1] / "low_tray_pick.yaml")


@pytest.fixture(scope="module")
def planned():
    scenario = load_scenario(SCENARIO)
    world = ways.nominal(scenario, nominal_plant(scenario))
    return scenario, world


def test_the_straight_approach_is_found_to_sweep_through_the_next_part(planned):
    """Without a via, the planning model finds pick 1's approach inside box 'second', named by its
    bodies (sampled at most 5 mm apart), and nothing else."""
    scenario, world = planned
    plan = pick_plan(scenario.pick, (), route.plan_vias(scenario, world))
    scene = obstacles.PlanningScene(scenario)
    found = (obstacles.way_hit(scene, world, plan, i) for i in obstacles.checked_segments(plan))
    hits = {h.phase: h for h in found if h}
    assert set(hits) == {"approach"}
    assert hits["approach"].task == 1 and hits["approach"].bodies == ("hand", "second")
    assert hits["approach"].distance < 0.0
    assert obstacles.STEP <= 0.005


def test_the_routed_plan_goes_above_and_keeps_clear(planned):
    """The routed plan has a via above that way; no checked way of it hits."""
    scenario, world = planned
    vias = route.routed_vias(scenario, world)
    assert {(v.task, v.phase) for v in vias} == {(1, "approach")}
    plan = pick_plan(scenario.pick, (), vias)
    assert obstacles.obstacle_warnings(scenario, world, plan) == []
    for v in vias:  # above both ends of the way it splits: the tool rises first, arrives from above
        assert v.position[2] >= 0.19


@pytest.mark.slow
def test_the_re_routed_pick_places_both_parts(run):
    m = run(SCENARIO).metrics
    assert m["status"] == "ok", m["reasons"]
    for p in m["picks"]:
        assert p["grasped"] and p["placed"] and not p["collision"], p
        assert p["place_error_mm"] <= 3.0 and p["place_error_deg"] <= 3.0, p
        assert p["attempts"] == 1
