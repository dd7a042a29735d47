"""Issue 33: a way past an arm's own waist axis — the inner edge of its top-down workspace — goes
around it (``worlds.pick.route``, tests/unit/test_pick_route.py); where no way around is found it is
warned about before the run (``worlds.pick.singularity.inner_reach_warnings``)."""

from pathlib import Path
from types import SimpleNamespace

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick import route
from ptint_drake.worlds.pick.singularity import inner_reach_warnings

TESTS = Path(__file__).resolve().parents[1]
START_6DOF = [22.7, 46.5, 20.0, 0.0, 21.5, 0.0]


def _reach(scenario) -> list:
    """The warnings of the plan a run makes (its vias included), on the arm's model."""
    arm = nominal_plant(scenario)
    return inner_reach_warnings(scenario, SimpleNamespace(arm=arm, plan=route.routed_plan(scenario, arm=arm)))


def test_a_way_from_a_tray_on_one_side_to_a_part_on_the_other_goes_around_and_is_not_warned():
    assert _reach(load_scenario(str(TESTS / "two_belt_pick_mirrored.yaml"))) == []


def test_the_way_is_warned_where_no_way_around_is_found(monkeypatch):
    """two_belt_pick_mirrored with no via found: pick 1's approach swings from the tray (y = −0.24
    m) to the block 113 mm from the waist axis (its way under the error dynamics), where rvm1_5dof
    has no top-down posture 73 mm from the axis; measured before the route, it slid into that edge
    and missed."""
    monkeypatch.setattr(route, "_via_for", lambda *args: None)
    warnings = _reach(load_scenario(str(TESTS / "two_belt_pick_mirrored.yaml")))
    assert len(warnings) == 1, warnings
    assert warnings[0].startswith("reach: pick 1's approach passes 113 mm from the waist axis of rvm1_5dof")
    assert "no way around the base was found" in warnings[0]


def test_the_same_tray_moved_to_the_parts_side_is_not_warned():
    scenario = load_scenario(str(TESTS / "two_belt_pick_mirrored.yaml"))
    scenario.pick.tray.center = [0.08, 0.24, 0.10]
    assert _reach(scenario) == []


def test_the_bundled_pick_scenarios_and_the_six_joint_arm_are_not_warned():
    for name in ("conveyor_pick_place", "assembly_pick_place"):
        assert _reach(load_scenario(name)) == [], name
    six = load_scenario(str(TESTS / "two_belt_pick_mirrored.yaml"))
    six.robot.model, six.robot.initial_q_deg = "rvm1_6dof", START_6DOF
    assert _reach(six) == []
