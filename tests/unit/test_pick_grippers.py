"""Issue 33: the datasheet grippers — their ranges (exit 2 outside them) and the payload warning."""

import json

import pytest

from ptint_drake.cli import main


def _run(tmp_path, *overrides):
    args = ["run", "conveyor_pick_place", "--no-replay", "--no-figures", "--out", str(tmp_path / "o")]
    for o in overrides:
        args += ["--set", o]
    return main(args)


@pytest.mark.parametrize("model, field, value", [
    ("schunk_wsg_50_110", "max_force", 4.0), ("schunk_wsg_50_110", "max_force", 81.0),
    ("schunk_wsg_50_110", "speed", 0.5), ("robotiq_2f_85", "max_force", 19.0),
    ("robotiq_2f_85", "max_force", 240.0), ("robotiq_2f_85", "speed", 0.01), ("robotiq_2f_85", "speed", 0.16),
])
def test_force_or_speed_outside_the_datasheet_is_one_line_exit_2(tmp_path, capsys, model, field, value):
    code = _run(tmp_path, f"pick.gripper.model={model}", f"pick.gripper.{field}={value}")
    err = capsys.readouterr().err.strip()
    assert code == 2 and f"pick.gripper.{field}" in err and model in err and len(err.splitlines()) == 1, err


def test_gripper_and_part_beyond_the_payload_are_warned_about_naming_the_masses(tmp_path, capsys):
    """The WSG 50-110 (1.2 kg) with a 0.1 kg part on the RV-M1 (1.2 kg rated, hand included):
    warned before the run, and it still places the part (the arm's controller is model-free)."""
    code = _run(tmp_path, "pick.gripper.model=schunk_wsg_50_110", "pick.gripper.max_force=40")
    err = capsys.readouterr().err
    assert "payload" in err and "1.20 kg" in err and "0.10 kg" in err and "1.2 kg" in err, err
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert code == 0 and m["picks"][0]["placed"] and not m["picks"][0]["collision"], m["picks"]
    assert any("payload" in w for w in m["warnings"])


def test_the_robotiq_within_the_payload_is_not_warned_about_and_places(tmp_path, capsys):
    code = _run(tmp_path, "pick.gripper.model=robotiq_2f_85", "pick.gripper.max_force=60",
                "pick.gripper.speed=0.1")
    err = capsys.readouterr().err
    m = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert code == 0 and "payload" not in err, err
    p = m["picks"][0]
    assert p["placed"] and not p["collision"], p
    assert p["place_error_mm"] <= 3.0 and p["place_error_deg"] <= 3.0, p
