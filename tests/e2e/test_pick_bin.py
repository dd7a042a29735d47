"""Issue 44: a bin as a destination (tests/bin_pick.yaml: conveyor_pick_place's part off its belt
into an open box) — the part ends in the bin, counted "in the bin" with no mm criterion; a bin too
narrow for the part leaves it on the walls, named ``not in the bin``; bad bin input gets one line
naming the field and exit 2, nothing written."""

from pathlib import Path

import numpy as np
import pytest

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.scene import in_bin

SCENARIO = str(Path(__file__).resolve().parents[1] / "bin_pick.yaml")


def test_the_part_ends_in_the_bin(run):
    result = run(SCENARIO)
    m = result.metrics
    assert m["status"] == "ok", m["reasons"]
    (p,) = m["picks"]
    assert p["bin"] == "bin" and p["slot"] is None
    assert p["grasped"] and p["held_at_place"] and p["in_bin"] and p["placed"] and not p["collision"], p
    # the truth at the end, read from the probe's log: the part's centre on the bin's floor
    box = load_scenario(SCENARIO).pick.bins[0]
    centre = result.series["probe"][-1, 0:3]
    assert in_bin(box, centre)
    assert centre[2] == pytest.approx(box.center[2] + 0.015, abs=0.003)  # resting on the floor (30 mm cube)
    assert np.hypot(*(centre[:2] - box.center[:2])) < box.size[0] / 2


def test_a_bin_too_narrow_for_the_part_is_named_not_in_the_bin(run):
    m = run(SCENARIO, ("pick.bins[0].size=[0.02, 0.02, 0.05]",)).metrics
    (p,) = m["picks"]
    assert p["grasped"] and p["held_at_place"] and not p["in_bin"] and not p["placed"], p
    assert m["status"] != "ok" and "pick 0: not in the bin" in m["reasons"], m["reasons"]


BAD = {
    "both a slot and a bin": (("pick.tasks[0].slot=0",), "pick.tasks[0].slot", "exactly one of slot"),
    "neither a slot nor a bin": (("pick.tasks[0].bin=''",), "pick.tasks[0].slot", "exactly one of slot"),
    "no such bin": (("pick.tasks[0].bin=crate",), "pick.tasks[0].bin", "no bin named 'crate'"),
    "a bin out of reach": (("pick.bins[0].center=[0.6, 0.6, 0.06]",), "pick.bins[0]", "outside what the arm"),
    "a bin of two sizes": (("pick.bins[0].size=[0.1, 0.1]",), "pick.bins[0].size", "needs 3 values"),
    "a bin without walls": (("pick.bins[0].wall=0",), "pick.bins[0].wall", "must be positive"),
    "a bin named as the belt": (("pick.bins[0].name=belt", "pick.tasks[0].bin=belt"), "pick.bins[0].name",
                                "taken"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_bin_input_is_one_line_naming_the_field_and_exit_2(tmp_path, ptint_here, case):
    overrides, field, detail = BAD[case]
    out = tmp_path / "out"
    args = ["run", SCENARIO, "--quiet", "--no-replay", "--no-figures", "--out", out]
    for override in overrides:
        args += ["--set", override]
    result = ptint_here(*args)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    message = lines[0].removeprefix("ptint: error: ").removeprefix("--set: ")  # (checked as it is set)
    assert lines[0].startswith("ptint: error: ") and message.startswith(field) and detail in message, lines[0]
    assert not out.exists()
