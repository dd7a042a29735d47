"""Issue 45, every world on each bundled industrial arm: a pose task (``pose_ARM``) and a pick with a
real-size gripper (``pick_ARM``) per arm."""

import numpy as np
import pytest
from conftest import assert_prescribed_time
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.robot.rvm1 import model_path

ARMS = ("iiwa14", "panda", "ur5e")


def _inside_limits(arm: str, q: np.ndarray) -> bool:
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path(arm)))
    plant.Finalize()
    q = q if q.shape[-1] == plant.num_positions() else q.T
    return bool(np.all(q >= plant.GetPositionLowerLimits()) and np.all(q <= plant.GetPositionUpperLimits()))


@pytest.mark.parametrize("arm", ARMS)
def test_pose_meets_criteria(run, arm):
    """``pose_ARM``: the tool meets the tumbling object within 1 mm and 2° at tf, not before tf/2
    (in distance and in angle), holds it within 3 mm / 5°, and no joint leaves its range."""
    result = run(f"pose_{arm}")
    m = result.metrics
    assert m["status"] == "ok", m.get("reasons")
    assert_prescribed_time(m, f"pose_{arm}")
    seg = m["segments"][0]
    assert seg["e_tf_norm"] <= 1e-3 and seg["e_rot_tf_deg"] <= 2.0, (seg["e_tf_norm"], seg["e_rot_tf_deg"])
    assert seg["e0_norm"] > 0.04 and seg["e_rot0_deg"] > 30.0
    assert seg["e_half_norm"] >= 0.25 * seg["e0_norm"] and seg["e_rot_half_deg"] >= 0.25 * seg["e_rot0_deg"]
    assert seg["e_hold_max_norm"] <= 3e-3 and seg["e_rot_hold_max_deg"] <= 5.0
    assert _inside_limits(arm, np.asarray(result.series["q"]))


@pytest.mark.slow
@pytest.mark.parametrize("arm", ARMS)
def test_pick_places_every_yawed_part(run, arm):
    """``pick_ARM``: three parts, each turned, riding a belt at ≥ 0.1 m/s, grasped by the arm's
    real-size gripper and placed within 3 mm and 3° of their slots, with no collision, no joint out
    of its range."""
    result = run(f"pick_{arm}")
    m, pick = result.metrics, result.scenario.pick
    assert len(pick.parts) >= 3 and all(abs(p.yaw_deg) >= 10.0 for p in pick.parts)
    assert all(b.speed >= 0.1 for b in pick.belts)
    assert pick.gripper.model in ("schunk_wsg_50_110_full", "robotiq_2f_85_full", "panda_hand")
    assert m["status"] == "ok", m.get("reasons")
    assert len(m["picks"]) == len(pick.parts)
    for p in m["picks"]:
        assert p["placed"] and not p["collision"], p
        assert p["place_error_mm"] <= 3.0 and p["place_error_deg"] <= 3.0, p
    assert _inside_limits(arm, np.asarray(result.series["q"]))


def test_list_names_a_curve_a_pose_and_a_pick_per_arm(ptint_here):
    names = {line.split()[0] for line in ptint_here("list").stdout.splitlines() if line.strip()}
    assert {f"{w}_{arm}" for w in ("curve", "pose", "pick") for arm in ARMS} <= names


def test_hand_and_part_over_the_panda_payload_is_warned_before_the_run():
    """The Panda hand (0.73 kg) with a 2.5 kg part is over the Panda's 3 kg: warned before the run,
    naming both masses; the bundled 0.1 kg parts are not."""
    from ptint_drake.simulation import build
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text

    name, text = scenario_text("pick_panda")
    assert not build(parse_with_overrides(text, (), name), log=False).pre_run_warnings()
    heavy = parse_with_overrides(text, ("pick.parts[1].mass=2.5",), name)
    (warning,) = build(heavy, log=False).pre_run_warnings()
    assert "0.73 kg" in warning and "2.50 kg" in warning and "3 kg" in warning, warning


@pytest.mark.parametrize("arm", ("iiwa14", "panda"))
def test_the_long_sequence_has_twenty_picks_in_sixty_seconds_over_120_degrees(arm):
    """scripts/posture_sequence.py's scenario (issue 45's 60 s sequence) passes the pick world's checks
    before a run (reach, belt clearance) and is what the issue asks: ≥ 20 picks, ≤ 60 s, the parts
    taken at base azimuths ≥ 120° apart.  (The 60 s runs themselves are the script's, not a test's.)"""
    import math

    from script_module import load_script

    from ptint_drake.simulation import build
    from ptint_drake.simulation.scenario import parse_scenario

    module = load_script("posture_sequence")
    scenario = parse_scenario(module.scenario(arm), f"sequence_{arm}")
    assert len(scenario.pick.tasks) >= 20 and scenario.duration <= 60.0
    azimuths = [math.degrees(math.atan2(b.center[1], b.center[0])) for b in scenario.pick.belts]
    assert max(azimuths) - min(azimuths) >= 120.0 - 0.01  # (centres written to 0.1 mm)
    build(scenario, log=False)
