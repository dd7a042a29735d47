"""Issue 44: the harsh Monte Carlo on the short assembly line (``ptint robust line_assembly``) —
three samples, the property that matters: every part placed with no collision, or its failure
named; a part that cannot be held counted apart; the belts at their drawn speeds while the
controller side was told none; each close command as late or early as drawn; CPU seconds per
sample reported.  (The 50-sample study is docs/pick_place.md's table: too long for a test.)

Sample 8 ran away before the give-up rule (``line.give_up``): cube_2's grasp was planned 0.12 s
before its deadline, conveyor3 (no encoder) then seen at 0.122 m/s, and the targets followed the
part to the edge of reach — joint 3 at 19 rad/s against its 3 rad/s, collision with conveyor1,
conveyor3 and cube_2.  With the via's legs split by the model (``line.via_split``) and the slot of
the shorter cycle (``line.slot_choice``) it placed all three at commit 7100bb4; since the approach
is never shorter than the model's (c071eea) cube_2 is given up again, ``not reachable in time``
with no task (measured at 40773c0).  The rule's own cases are tests/unit/test_line_give_up_rule.py.
Here: every part placed or given up by name, and no joint past its speed or position limit."""

import json

import pytest

from ptint_drake.config.pick import GripperConfig, PickTaskConfig


@pytest.mark.slow
def test_a_harsh_line_study_places_or_names_every_part(tmp_path, ptint_here):
    # seeds 6 to 8: a close 54 ms early (seed 6, part 0: before the grasp latch took the part's
    # velocity at the close command, a runaway into conveyor1), a 0.93 kg part at friction 0.06 that
    # no grasp can lift (seed 7, part 2), belts between 0.07 and 0.17 m/s against 0.1 declared, and
    # the sample that ran away before the give-up rule (seed 8: the module docstring)
    out = tmp_path / "robust"
    done = ptint_here("robust", "line_assembly", "--samples", "3", "--seed", "6", "--workers", "1",
                      "--quiet", "--out", out)
    assert done.returncode == 0, done.stderr
    result = json.loads((out / "robust.json").read_text())
    rows = json.loads((out / "samples.json").read_text())
    assert result["placed_with_collision"] == 0
    # seed 7's ~0.95 kg cube on links x1.2 ran away at the min-tf phases planned to the full effort
    # limits (docs/pick_place.md: 0.860 over 50 samples); at two thirds of them
    # (phase_time.TORQUE_SHARE) every part a grasp can hold is placed, but seed 8's third, given up,
    # and seed 6's third: on a belt at 0.068 m/s it comes into reach too late for a task to end
    # within the run's 14.5 s, since the first cube is gripped across the faces that need no turn on
    # its carry (``line.grip``: its approach turns 67.5°, the first task ends 0.3 s later)
    assert result["cannot_be_held"] == 1 and result["pick_success_rate_holdable"] == pytest.approx(6 / 8)
    assert result["pick_success_rate"] == pytest.approx(6 / 9)
    assert result["cpu_s_per_sample"]["mean"] > 0.0 and all(r["cpu_s"] > 0.0 for r in rows)
    # each run's simulated time (a line's ends when it is done: ``line.truth.run_end``), summarised
    assert all(r["simulated_s"] > 0.0 for r in rows)
    assert result["simulated_s_per_sample"]["max"] == max(r["simulated_s"] for r in rows)
    lead = 0.5 * PickTaskConfig().margin / GripperConfig().speed  # the close before the grasp time
    # seed 6's third task, kept at 10.1 s after its belt showed 0.068 m/s (0.1 declared), has its
    # lift and carry at least the model's tfs from where the part is then (``line.watch.ahead``);
    # planned at the decision's belief, its carry drove joint 1 to 3.56 rad/s against its 3 (4c93d1b)
    # seed 7's first carry, planned turning the tool +90° (the wrist's roll 5°), was turned −90° by
    # the top-down task (its branch nearest the tool's actual yaw), the roll 176° at 4.49 rad/s
    # against its 4 (e58b1cd); a near-quarter turn is now planned the slower way round
    # (``route.turn_ways``).  No sample has a joint past its speed or position limit.
    assert [row["warnings"] for row in rows] == [[], [], []]
    named = {6: "on the belt at the end", 8: "not reachable in time"}  # (no task: not started)
    for seed, reason in named.items():
        (row,) = [row for row in rows if row["seed"] == seed]
        assert [p["placed"] for p in row["picks"]] == [True, True, False], row["picks"]
        assert row["picks"][2]["reason"] == reason and row["picks"][2]["task"] is None, row["picks"]
    for row in rows:
        params = row["params"]
        assert len(row["picks"]) == 3 and params["belt_encoder"] == [False] * 3
        assert all(0.05 <= v <= 0.2 for v in params["belt_speed"])
        assert max(abs(v / 0.1 - 1.0) for v in params["belt_speed"]) > 0.3
        for k, pick in enumerate(row["picks"]):
            assert (pick["placed"] and not pick["collision"]) or pick["reason"], pick
            given_up = pick["reason"] in named.values() and pick["task"] is None
            assert pick["placed"] == params["holdable"][k] or given_up, (row["seed"], pick)
            if pick["task"] is not None:  # the truth's close jitter on the task that picked part k
                planned = pick["t_grasp_prescribed"] - lead
                assert pick["t_close_command"] - planned == pytest.approx(params["close_delay"][k], abs=1e-9)
    (unheld,) = [p for r in rows for p, h in zip(r["picks"], r["params"]["holdable"]) if not h]
    assert unheld["reason"] in ("dropped", "missed after retry", "not placed"), unheld

