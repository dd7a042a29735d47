"""The reachability check before a run covers the orientation a task asks for (issue 19): a pose
the arm cannot take at tf is one line naming ``interceptions[i].target.orientation``, exit 2,
nothing written; the bundled orientation scenarios pass it."""

import pytest

from ptint_drake import cli
from ptint_drake.robot.plant import make_plant
from ptint_drake.robot.reachability import check_reachable
from ptint_drake.simulation.scenario import ScenarioError, load_scenario, parse_scenario
from ptint_drake.worlds.registry import schedule_of, world_of

# x = 0.48 m at z = 0.15 m: within the reach of rvm1_5dof's tool (up to ~0.54 m there), but not
# with the tool pointing down (the wrist would have to stand 0.12 m above it, out of reach)
FAR_OUT = """
duration: 1.0
robot: {model: rvm1_5dof, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0, 0.0, 0.0]}
controller: {task: top_down}
interceptions:
  - {start: 0.0, tf: 0.5, beta: 0.75,
     target: {linear: {start: [0.48, 0.0, 0.15], velocity: [0.0, 0.0, 0.0]},
              orientation: {rpy_deg: [0.0, 0.0, 30.0]}}}
"""

# rvm1_6dof at the same point with the approach axis (tool z) pointing back at the base
BACKWARDS = """
duration: 1.0
robot: {model: rvm1_6dof, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0, 0.0, -45.0, 0.0]}
controller: {task: pose}
interceptions:
  - {start: 0.0, tf: 0.5, beta: 0.75,
     target: {linear: {start: [0.48, 0.0, 0.15], velocity: [0.0, 0.0, 0.0]},
              orientation: {rpy_deg: [0.0, -90.0, 0.0]}}}
"""


@pytest.mark.parametrize("name", ["conveyor_yaw", "curve_pose"])
def test_the_bundled_orientation_scenarios_are_reachable(name):
    scenario = load_scenario(name)
    reach(scenario)


def test_an_unreachable_top_down_grasp_is_one_line_exit_2(tmp_path, capsys):
    path = tmp_path / "far_out.yaml"
    path.write_text(FAR_OUT)
    out = tmp_path / "out"
    assert cli.main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert err.startswith("ptint: error: interceptions[0].target.orientation: the arm cannot reach a "
                          "top-down grasp"), err
    assert "t = 0.500 s" in err and not out.exists()
    # the position alone is reachable: the same point with task position passes the check
    scenario = parse_scenario(FAR_OUT.replace("task: top_down", "task: position"))
    reach(scenario)


def test_an_unreachable_pose_names_the_orientation():
    scenario = parse_scenario(BACKWARDS)
    assert scenario.controller.task == "pose" and scenario.robot.model == "rvm1_6dof"
    with pytest.raises(ScenarioError, match=r"^interceptions\[0\]\.target\.orientation: the arm cannot "
                                            r"reach the orientation rpy \[0\.0, -90\.0, 0\.0\] deg"):
        reach(scenario)


@pytest.mark.parametrize("angles, hint", [("", True), (", initial_q_deg: [22.5, 45.0, 30.0, 0.0]", False)])
def test_a_joint_count_mismatch_names_the_field_and_says_when_it_is_the_default(angles, hint):
    text = FAR_OUT.replace(", initial_q_deg: [22.5, 45.0, 30.0, 0.0, 0.0]", angles)
    scenario = parse_scenario(text, "mismatch")
    with pytest.raises(ScenarioError) as error:
        make_plant(scenario)
    message = str(error.value)
    assert message.startswith("robot.initial_q_deg: the model has 5 joints, got ")
    assert ("the default, the 3-joint rvm1's" in message) == hint and "\n" not in message


def reach(scenario) -> None:
    """``check_reachable`` with the interception world's schedule and objects."""
    check_reachable(make_plant(scenario), scenario, schedule_of(scenario),
                    world_of(scenario).objects(scenario))
