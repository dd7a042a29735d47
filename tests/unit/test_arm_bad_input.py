"""Issue 45's bad input on the bundled arms: an unknown ``robot.model`` is one line naming the field
and exit 2 in every command that reads a scenario (the studies too: they used to fan the runs out
and report each as failed, exit 0); a gripper plus a part over the arm's rated payload is warned
before the run, with the gripper's mass as built on the plant and the part's."""

import re

import pytest

from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text
from ptint_drake.worlds import runner
from ptint_drake.worlds.registry import world_of

COMMANDS = {
    "run": ("run", "curve_iiwa14", "--quiet"),
    "diagram": ("diagram", "curve_panda"),
    "tune": ("tune", "curve_ur5e", "--quiet"),
    "compare": ("compare", "curve_iiwa14", "--quiet"),
    "robust": ("robust", "curve_panda", "--samples", "2", "--quiet"),
    "sweep": ("sweep", "curve_ur5e", "--quiet"),
    "pick": ("run", "pick_iiwa14", "--quiet"),
}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_unknown_model_is_one_line_and_exit_2(tmp_path, ptint_here, command):
    out = tmp_path / "out"
    result = ptint_here(*COMMANDS[command], "--out", out, "--set", "robot.model=iiwa15")
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    expected = "ptint: error: --set: robot.model: 'iiwa15' is neither a bundled model"
    assert lines[0].startswith(expected), lines[0]
    assert "iiwa14, panda" in lines[0] and "ur5e" in lines[0]
    assert not out.exists()


# (scenario, part mass that takes gripper + part over the rated payload, gripper, its mass as built,
#  the arm's rated payload in kg including the hand; models/README.md)
OVER = {
    "iiwa14": ("pick_iiwa14", 13.0, "schunk_wsg_50_110_full", 1.2, 14.0),
    "panda": ("pick_panda", 2.5, "panda_hand", 0.73, 3.0),
    "ur5e": ("pick_ur5e", 4.5, "robotiq_2f_85_full", 0.925, 5.0),
    "rvm1_5dof": ("conveyor_pick_place", 1.15, "rvm1_gripper", 0.14, 1.2),
}


def _warnings(name: str, overrides=()) -> list[str]:
    _, text = scenario_text(name)
    scenario = parse_with_overrides(text, list(overrides), name)
    return world_of(scenario).prepare(scenario, log=False).pre_run_warnings()


@pytest.mark.parametrize("arm", sorted(OVER))
def test_payload_over_the_rating_is_warned_naming_both_masses(arm):
    name, part_kg, gripper, gripper_kg, rated = OVER[arm]
    assert not [w for w in _warnings(name) if w.startswith("payload")]  # the bundled parts fit
    (warning,) = [w for w in _warnings(name, [f"pick.parts[0].mass={part_kg}"]) if w.startswith("payload")]
    m = re.fullmatch(rf"payload: gripper {gripper} ([\d.]+) kg \+ part 'part1?' ([\d.]+) kg = ([\d.]+) kg "
                     rf"exceeds the {arm}'s rated payload of {rated:g} kg \(including the hand\)", warning)
    assert m, warning
    built_kg, part, total = (float(g) for g in m.groups())
    # the gripper as built on the plant: the full-size ones' datasheet masses, the RV-M1 hand's 0.14 kg
    assert built_kg == pytest.approx(gripper_kg, abs=0.0051)  # printed to 10 g
    assert part == part_kg and total == pytest.approx(gripper_kg + part_kg, abs=0.0051)  # printed to 10 g
    assert built_kg + part_kg > rated
    # just under the rating: no warning
    under = round(rated - built_kg - 0.02, 2)
    assert not [w for w in _warnings(name, [f"pick.parts[0].mass={under}"]) if w.startswith("payload")]


def test_payload_warning_comes_before_the_simulator_exists(monkeypatch):
    """``simulate`` hands the warning to ``warn`` before it makes the simulator (stopped there)."""
    _, text = scenario_text("pick_panda")
    scenario = parse_with_overrides(text, ["pick.parts[1].mass=2.6"], "pick_panda")
    warned = []

    def no_simulator(run):
        raise RuntimeError("stopped before the simulator")
    monkeypatch.setattr(runner, "make_simulator", no_simulator)
    with pytest.raises(RuntimeError, match="stopped before the simulator"):
        runner.simulate(scenario, warn=warned.append)
    expected = "payload: gripper panda_hand 0.73 kg + part 'part2' 2.60 kg"
    assert any(w.startswith(expected) for w in warned), warned
