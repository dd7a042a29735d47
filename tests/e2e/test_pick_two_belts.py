"""Issue 33: a two-belt pick and place nobody tuned (tests/two_belt_pick.yaml: a 0.35 kg cylinder at
0.15 m/s, a turned box on a diagonal belt, a turned tray), every controller setting left at its
default, places both parts on the 5-joint and the 6-joint arm."""

from pathlib import Path

import pytest

SCENARIO = str(Path(__file__).resolve().parents[1] / "two_belt_pick.yaml")
# rvm1_6dof's start posture (tests/unit/test_pick_arm6.py): forearm roll 0, wrist pitched 21.5°
ARMS = {"rvm1_5dof": "", "rvm1_6dof": "robot: {model: rvm1_6dof, end_effector: tool, initial_q_deg: "
                                      "[22.7, 46.5, 20.0, 0.0, 21.5, 0.0]}"}


@pytest.mark.slow
@pytest.mark.parametrize("arm", sorted(ARMS))
def test_an_untuned_two_belt_scenario_places_both_parts(run, arm):
    m = run(SCENARIO, ARMS[arm]).metrics
    assert m["status"] == "ok", (arm, m["reasons"])
    assert len(m["picks"]) == 2
    for p in m["picks"]:
        assert p["grasped"] and p["placed"] and not p["collision"], (arm, p)
        assert p["place_error_mm"] <= 3.0 and p["place_error_deg"] <= 3.0, (arm, p)
        assert p["attempts"] == 1 and p["state_at_place"] == "holding", (arm, p)
