"""Issue 33: the 6-joint arm on pick scenarios — the singularity warning before the run."""

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.world import PickWorld

# rvm1_6dof's start posture for the bundled pick scenarios: the tool at conveyor_pick_place's
# start point pointing down, forearm roll 0, the wrist pitched 21.5° (clear of its singularity at 0)
START_6DOF = [22.7, 46.5, 20.0, 0.0, 21.5, 0.0]


def _warnings(name: str, model: str, q: list, damping: float = 0.0) -> list:
    scenario = load_scenario(name)
    scenario.robot.model, scenario.robot.initial_q_deg = model, q
    scenario.controller.pinv_damping = damping
    return [w for w in PickWorld().prepare(scenario).pre_run_warnings() if w.startswith("singularity")]


def test_a_place_next_to_the_base_crosses_the_wrist_singularity_and_is_warned_about():
    """assembly_pick_place's tray is 0.25 m from the waist axis: the forearm hangs vertical over it
    (wrist pitch ≈ 0 on the elbow-up branch): the way to the first slot passes the singularity."""
    warnings = _warnings("assembly_pick_place", "rvm1_6dof", START_6DOF)
    assert warnings and warnings[0].startswith("singularity: pick 0's"), warnings
    assert all("rvm1_6dof" in w and "pinv_damping" in w for w in warnings), warnings
    damped = _warnings("assembly_pick_place", "rvm1_6dof", START_6DOF, damping=0.01)
    assert len(damped) == len(warnings) and not any("pinv_damping" in w for w in damped), damped


def test_the_five_joint_arm_is_not_checked():
    assert _warnings("assembly_pick_place", "rvm1_5dof", [22.5, 45.0, 30.0, 0.0, 0.0]) == []



def test_a_six_joint_top_down_task_is_damped_by_default_and_nothing_else_is():
    """controller.pinv_damping left out: 0.015 m/rad for top_down on 6 joints (docs/pick_place.md),
    the exact J⁺ for the 5-joint arm and the other tasks; a value written is kept."""
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415

    _, text = scenario_text("conveyor_pick_place")
    six = ["robot.model=rvm1_6dof", f"robot.initial_q_deg={START_6DOF}"]
    assert parse_with_overrides(text, six).controller.pinv_damping == 0.015
    assert parse_with_overrides(text, six + ["controller.pinv_damping=0"]).controller.pinv_damping == 0.0
    assert load_scenario("conveyor_pick_place").controller.pinv_damping == 0.0
    assert load_scenario("curve_pose").controller.pinv_damping == 0.0  # pose on rvm1_6dof: exact
