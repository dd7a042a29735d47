"""Issue 44: the line's phase times come from the minimum phase time model
(``worlds.pick.line.cycle`` over ``phase_time.PhaseTimes``) — a track's lead is the approach's and
the descend's min tf from the tool's point, the chosen task's tfs are ``cycle_time``'s, and the
capacity estimate is 60 / the model's cycle."""

import numpy as np
import pytest

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.cycle import LineCycles
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.phase_time import PhaseTimes, cycle_time


@pytest.fixture(scope="module")
def cycles():
    """The min-tf model of line_short's station (the expanded scenario, as the run builds it)."""
    scenario, _ = line_scenario(load_scenario("line_short"))
    return LineCycles(scenario)


def cube(s: float) -> Track:
    """A cube on line_short's belt (x = 0.25 m, +y at 0.1 m/s, top at 0.135 m), ``s`` m along it."""
    return Track(0, "cube", "conveyor", (0.25, s, 0.15), s, (0.0, 1.0, 0.0), 0.1, (1.0, 0.0, 0.0),
                 0.03, 0.0212)


def test_a_lead_is_the_models_approach_and_descend_from_the_tool(cycles):
    start, part = np.array([0.13, 0.2, 0.15]), cube(-0.1)
    lead = cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0)
    model, up, ride = cycles.model, np.array([0.0, 0.0, 0.04]), np.array([0.0, 0.1, 0.0])
    approach = model.min_tf(start, np.asarray(part.position) + up, ride, 0.0, 0.75, (0.0, 0.0))
    at = np.asarray(part.position) + ride * approach
    descend = max(model.min_tf(at + up, at, ride, 0.0, 0.75, (0.0, 0.0)), 0.012 / model.gripper_speed)
    assert lead == pytest.approx(approach + descend, rel=1e-6)
    # from farther away the lead is longer; from the same point it is the cached one
    assert cycles.lead(part, (-0.3, 0.3), 5.0, start + [0.0, 0.1, 0.0], 0.0) > lead
    assert cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0) == lead


def test_the_tasks_tfs_are_the_models_cycle_and_the_descend_ends_at_the_grasp(cycles):
    start, part = np.array([0.13, 0.2, 0.15]), cube(-0.1)
    lead = cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0)
    grasp = 5.0 + np.ceil(lead / 0.1) * 0.1
    cycle = cycles.phases(part, (-0.3, 0.3), grasp, 5.0, start, 0.0, 3)
    task = cycles.task_of("cube_0", 3, grasp, 5.0, cycle)
    assert task.start + task.approach.tf + task.descend.tf == pytest.approx(grasp)
    assert task.approach.tf >= cycle.phases["approach"] - 1e-9  # stretched to the grid, never shorter
    for phase in ("descend", "lift", "carry", "place", "retreat"):
        assert getattr(task, phase).tf == cycle.phases[phase]
    # the carry is the model's for the payload held: a heavier part gets a carry no shorter
    heavy = cycle_time(cycles.model, part.at(task.start, 5.0), np.array([0.0, 0.1, 0.0]),
                       np.array([0.13, 0.2, 0.125]), mass=2.0, start=start, yaw=0.0)
    light = cycle_time(cycles.model, part.at(task.start, 5.0), np.array([0.0, 0.1, 0.0]),
                       np.array([0.13, 0.2, 0.125]), mass=0.1, start=start, yaw=0.0)
    assert heavy.phases["carry"] >= light.phases["carry"]
    assert isinstance(cycles.model, PhaseTimes)
