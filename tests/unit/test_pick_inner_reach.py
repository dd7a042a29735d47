"""Issue 33: a 5-joint arm's way past its own waist axis — the inner edge of its top-down workspace
— is warned about before the run (``worlds.pick.singularity.inner_reach_warnings``)."""

from pathlib import Path

from ptint_drake.scenario import load_scenario
from ptint_drake.worlds.pick.world import PickWorld

TESTS = Path(__file__).resolve().parents[1]
START_6DOF = [22.7, 46.5, 20.0, 0.0, 21.5, 0.0]


def _reach(scenario) -> list:
    return [w for w in PickWorld().prepare(scenario).pre_run_warnings() if w.startswith("reach:")]


def test_a_way_from_a_tray_on_one_side_to_a_part_on_the_other_is_warned_on_the_five_joint_arm():
    """two_belt_pick_mirrored: pick 1's approach swings from the tray (y = −0.24 m) to the block
    (y = +0.1 m) 115 mm from the waist axis (straight line), where rvm1_5dof has no top-down
    posture 75 mm from the axis; measured, it slid into that edge and missed."""
    warnings = _reach(load_scenario(str(TESTS / "two_belt_pick_mirrored.yaml")))
    assert len(warnings) == 1, warnings
    assert warnings[0].startswith("reach: pick 1's approach passes 115 mm from the waist axis of rvm1_5dof")


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
