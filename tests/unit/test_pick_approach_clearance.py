"""Issue 44: the part an approach goes to take is an obstacle of that approach (``obstacles``):
before the way's end, ``clearance`` above the part, the hand keeps ``HAND_MARGIN`` from it, and
where the straight way does not, the route's via lifts it over the part (the descend then comes
from above).  tests/low_tray_pick.yaml with its tray 30 mm higher (z = 0.08 m): the second
approach, from the tray's retreat point 55 mm below its end, grazes its own box at 1.9 mm — no
sample inside it, so the rule that counted only a sample inside let it pass without a via."""

import copy
from pathlib import Path

import numpy as np
import pytest

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick import obstacles, route, ways
from ptint_drake.worlds.pick.tasks import pick_plan

SCENARIO = str(Path(__file__).resolve().parents[1] / "low_tray_pick.yaml")


@pytest.fixture(scope="module")
def grazing():
    scenario = copy.deepcopy(load_scenario(SCENARIO))
    scenario.pick.tray.center = [0.16, 0.16, 0.08]
    return scenario, ways.nominal(scenario, nominal_plant(scenario))


def _own_distances(scene, world, plan, i: int, task: int) -> np.ndarray:
    """m: the hand's distance to task ``task``'s part along segment i's way, 1 mm apart at most."""
    s = plan.schedule.segments[i]
    coarse = ways.segment_way(world, plan, i, np.linspace(0.0, s.tf, 11))
    length = float(np.sum(np.linalg.norm(np.diff(coarse, axis=0), axis=1)))
    tau = np.linspace(0.0, s.tf, max(11, int(np.ceil(length / 0.001)) + 1))
    way = ways.segment_way(world, plan, i, tau)
    part = plan.segments[plan.segment_index(task, "approach")].index
    return np.array([scene.nearest(world, x, s.start + t, None, scene.radius[(task, "approach")], part)[0]
                     for x, t in zip(way, tau)])


def test_an_approach_grazing_its_own_part_is_a_hit(grazing):
    scenario, world = grazing
    plan = pick_plan(scenario.pick, (), route.plan_vias(scenario, world))
    scene = obstacles.PlanningScene(scenario)
    i = plan.segment_index(1, "approach")
    own = _own_distances(scene, world, plan, i, 1)
    assert 0.0 < own.min() < obstacles.HAND_MARGIN < own[-1]  # never inside it, but nearer than the margin
    hit = obstacles.way_hit(scene, world, plan, i)
    assert hit is not None and hit.bodies == ("hand", "second") and hit.distance < obstacles.HAND_MARGIN


def test_the_routed_approach_goes_over_its_own_part(grazing):
    scenario, world = grazing
    vias = route.routed_vias(scenario, world)
    assert {(v.task, v.phase) for v in vias} == {(1, "approach")}
    plan = pick_plan(scenario.pick, (), vias)
    scene = obstacles.PlanningScene(scenario)
    assert obstacles.obstacle_warnings(scenario, world, plan) == []
    j = next(n for n, s in enumerate(plan.segments) if s.task == 1 and s.phase == "via")
    for i in (j, j + 1):  # the via's leg and the approach after it
        assert _own_distances(scene, world, plan, i, 1).min() >= obstacles.HAND_MARGIN - 1e-6
    end = ways.segment_way(world, plan, j + 1, np.array([0.0, plan.schedule.segments[j + 1].tf]))
    assert end[0][2] > end[1][2]  # the approach arrives from above
