"""Issue 44: a run at the minimum phase times (tests/min_tf_pick.yaml: assembly_pick_place's cell,
every tf what ``worlds.pick.phase_time`` gives) places every part with no warning before or after
the run, and the joints' measured peak speeds stay within the model's limits (the model's margin
puts the planned peak at 1/1.15 of the limit); the picks per minute measured against the model's
cycle estimate."""

from pathlib import Path

import pytest

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.phase_time import MARGIN, capacity, task_cycles

SCENARIO = str(Path(__file__).resolve().parents[1] / "min_tf_pick.yaml")


@pytest.mark.slow
def test_a_run_at_the_model_tfs_places_every_part_within_the_joint_limits(run):
    m = run(SCENARIO).metrics
    assert m["status"] == "ok", m["reasons"]
    assert m["warnings"] == []  # none before the run (feasibility), none after (joint limits)
    for p in m["picks"]:
        assert p["placed"] and not p["collision"], p
        assert p["place_error_mm"] <= 3.0
        # the measured peak speed: within the limit, near the model's 1 / MARGIN (0.87)
        assert 0.7 / MARGIN < p["joint_speed_ratio"] <= 1.0, p["joint_speed_ratio"]
    rows = m["segments"]
    end = max(r["start"] + r["tf"] for r in rows)
    measured = 60.0 * len(m["picks"]) / end  # picks per minute, the first approach to the last retreat
    estimate = capacity(task_cycles(load_scenario(SCENARIO)))
    assert abs(measured / estimate - 1.0) <= 0.2, (measured, estimate)
