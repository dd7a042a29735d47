"""Issue 44: a task kept in its approach whose part leaves its reach window by the speed its
belt is seen at is given up (``line.give_up``), not followed to the edge of reach — the harsh
study's sample 8 (``ptint robust line_assembly --samples 1 --seed 8``): cube_2's grasp was
planned 0.12 s before its deadline, conveyor3 (no encoder) then seen at 0.122 m/s.  Without the
rule the targets followed the part and the arm ran away (joint 3 at 19 rad/s against its 3 rad/s,
collision with conveyor1, conveyor3, cube_2).  With the via's legs split by the model
(``line.via_split``) and the slot of the shorter cycle (``line.slot_choice``) the arm is there
earlier and places all three (commit 7100bb4); the rule's own cases are
tests/unit/test_line_give_up_rule.py.  Here: every part placed or named, no runaway."""

import json


def test_the_harsh_sample_that_ran_away_places_or_names_each_part_without_a_runaway(tmp_path, ptint_here):
    out = tmp_path / "robust"
    done = ptint_here("robust", "line_assembly", "--samples", "1", "--seed", "8", "--workers", "1",
                      "--quiet", "--out", out)
    assert done.returncode == 0, done.stderr
    (row,) = json.loads((out / "samples.json").read_text())
    assert row["warnings"] == []  # no joint past its speed or position limit
    assert not any(p["collision"] for p in row["picks"])
    for pick in row["picks"]:  # placed, or given up by name (no task)
        assert pick["placed"] or (pick["reason"] == "not reachable in time" and pick["task"] is None), pick
