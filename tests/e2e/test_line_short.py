"""Issue 44: the short line runs itself — parts arrive unannounced, the arm decides online which
to pick and when, places them, and every decision is in metrics.json ``line.decisions``."""

import json

from ptint_drake.config.pick import PickTaskConfig

REASONS = ("later deadline", "not reachable in time", "not in reach yet", "tray full")


def test_short_line_places_what_it_decides_and_logs_every_decision(tmp_path, ptint_here):
    out = tmp_path / "out"
    # 20 s of line_short (seed 0): four cubes released at 3.7, 9.8, 10.5 and 11.1 s
    ptint_here("run", "line_short", "--quiet", "--no-replay", "--no-figures", "--out", out,
               "--set", "duration=20")
    line = json.loads((out / "metrics.json").read_text())["line"]
    assert line["released"] == 4 and line["entered"] >= 3
    assert line["placed"] >= 2, line["parts"]
    lead = PickTaskConfig().approach.tf + PickTaskConfig().descend.tf
    chosen = [d for d in line["decisions"] if d["track"] is not None]
    assert len(chosen) >= 2
    for d in line["decisions"]:
        assert all(s["reason"] in REASONS or s["reason"].startswith("blocked") for s in d["skipped"]), d
        if d["track"] is not None:  # a grasp far enough ahead for the arm, before the deadline
            assert d["t"] + lead - 1e-6 <= d["grasp"] <= d["deadline"] + 1e-9, d
    # the rivals of a choice are named, and the choice was the part leaving reach first
    rivals = [d for d in chosen if d["skipped"]]
    assert rivals and all(any(s["reason"] == "later deadline" for s in d["skipped"]) for d in rivals)
    parts = line["parts"]
    by_task = {p["task"]: p for p in parts if p["task"] is not None}
    for d in chosen:  # each decided track became the task of that very part, in its slot
        assert by_task[d["task"]]["part"] == f"cube_{d['track']}"
    placed = [p for p in parts if p["placed"]]
    assert all(p["task"] is not None for p in placed)
    assert all(p["reason"] for p in parts if p["entered"] and not p["placed"])
    assert line["picks_per_minute"] == 60.0 * line["placed"] / 20.0
