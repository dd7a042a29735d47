"""Issue 44: which free tray slot a line's pick takes (``line.slot_choice``, catalog ``fill``)."""

from __future__ import annotations

import numpy as np
import pytest

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.line import check_line
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.cycle import LineCycles, kind_part
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.line.slot_choice import choose, nearest
from ptint_drake.worlds.pick.phase_time import Cycle, NoTfFits


@pytest.fixture(scope="module")
def two_belts():
    """line_two_belts' controller-side cell and its min-tf model."""
    scenario, _ = line_scenario(load_scenario("line_two_belts"))
    return scenario, LineCycles(scenario)


def test_the_two_free_slots_nearest_the_grasp_are_asked(two_belts):
    """The tray's column nearest the belts (x = 0.16 m: slots 2, 5, 8 …), the nearest row first."""
    scenario, _ = two_belts
    cube = kind_part(scenario.pick, "cube")
    assert nearest(scenario.pick, cube, list(range(8)), (0.30, 0.0, 0.15))[:2] == [2, 5]
    assert nearest(scenario.pick, cube, [0, 1, 3, 4, 6, 7], (0.22, 0.3, 0.15))[:2] == [7, 4]


def test_the_shorter_cycle_is_taken_and_one_without_a_tf_passed_over():
    cycles = {0: Cycle({"carry": 1.0}, 0.15), 1: Cycle({"carry": 0.8}, 0.15), 2: Cycle({"carry": 0.8}, 0.15)}

    def cycle_of(slot):
        if slot == 3:
            raise NoTfFits("no top-down posture")
        return cycles[slot]

    assert choose(cycle_of, [0, 1, 2])[0] == 1  # the first of a tie
    assert choose(cycle_of, [3, 0])[0] == 0
    with pytest.raises(NoTfFits):
        choose(cycle_of, [3])


def test_a_slot_with_no_cycle_makes_room_for_the_next_nearest_and_no_more_are_asked():
    """``choose`` asks the candidates nearest first until two have a cycle: one without (a phase
    with no tf, or no place yaw clearing the tray's parts) is passed over for the third nearest,
    and the fourth is not asked."""
    asked = []

    def cycle_of(slot):
        asked.append(slot)
        if slot == 5:
            raise NoTfFits("no place yaw at slot 5 keeps the open fingers clear of the tray's parts")
        return Cycle({"carry": 1.0 - 0.1 * slot}, 0.15)

    assert choose(cycle_of, [5, 0, 1, 2]) == (1, Cycle({"carry": 0.9}, 0.15))
    assert asked == [5, 0, 1]


def test_a_cube_from_the_outer_belt_goes_to_the_near_column_in_a_shorter_cycle(two_belts):
    """By the model: a cube grasped on the outer belt at the arm's side (y = 0) and the tool above
    it — the cycle to slot 2 (x = 0.16 m) is shorter than to slot 0 (x = 0.06 m: the listed
    order's first), and ``choose`` over the nearest two takes it."""
    scenario, cycles = two_belts
    track = Track(0, "cube", "outer", (0.30, -0.05, 0.15), -0.05, (0.0, 1.0, 0.0), 0.05, (1.0, 0.0, 0.0),
                  0.03, 0.0212)
    start = np.array([0.30, -0.05, 0.19])
    grasp = 2.0

    def cycle_of(slot):
        return cycles.phases(track, (-0.3, 0.3), grasp, 0.0, start, 0.0, slot)

    first, near = cycle_of(0).total, cycle_of(2).total
    assert near < first
    slot, cycle = choose(cycle_of, nearest(scenario.pick, kind_part(scenario.pick, "cube"), list(range(8)),
                                           track.at(grasp, 0.0)))
    assert slot in (2, 5) and cycle.total <= near + 1e-9


def test_an_unknown_fill_is_one_line_naming_the_field():
    scenario = load_scenario("line_two_belts")
    scenario.pick.line.catalog[1].fill = "nearest"
    with pytest.raises(ScenarioError, match=r"catalog\[1\].fill: 'nearest' is not one of cycle, order"):
        check_line(scenario.pick, scenario.duration, 0.06, 0.012)
