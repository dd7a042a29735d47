"""The friction bound of a two-finger grasp (worlds.pick.hold_limit) and its count in a study."""

import pytest

from ptint_drake.config.pick import GripperConfig, MoveConfig
from ptint_drake.worlds.pick.hold_limit import (G, hold_margin, lift_acceleration, pad_friction,
                                                 pair_friction)
from ptint_drake.worlds.pick.studies import holdable_counts, robust_summary


def test_the_bound_is_two_mu_f_over_the_weight_in_the_lift():
    lift = MoveConfig(0.4)
    a = lift_acceleration(0.05, lift)
    assert 1.0 < a < 10.0  # 5 cm in 0.4 s: a few m/s², not g-sized, not zero
    assert lift_acceleration(0.1, lift) == pytest.approx(2 * a)  # linear in the height
    assert lift_acceleration(0.05, MoveConfig(0.2)) > 3.5 * a  # ~ 1 / tf²
    mu = pair_friction(pad_friction("rvm1_gripper"), 0.4)
    assert mu == pytest.approx(2 * 1.0 * 0.4 / 1.4)  # the pads' μ 1.0 (models/rvm1_gripper.sdf)
    m = hold_margin(0.5, 0.4, GripperConfig(max_force=30.0), 0.05, lift)
    assert m == pytest.approx(2 * mu * 30.0 / (0.5 * (G + a)))
    # a kilogram at μ 0.05 in the RV-M1's 30 N fingers slips; 0.1 kg at μ 0.8 is held with room
    assert hold_margin(1.0, 0.05, GripperConfig(), 0.05, lift) < 1.0
    assert hold_margin(0.1, 0.8, GripperConfig(), 0.05, lift) > 10.0


def test_a_gripper_without_pads_is_named():
    with pytest.raises(Exception, match="gripper.model"):
        pad_friction("/nonexistent/gripper.sdf")


def test_parts_that_cannot_be_held_are_counted_apart():
    rows = [{"params": {"part_mass": [0.1, 1.0], "holdable": [True, False]},
             "picks": [{"placed": True}, {"placed": False}], "reasons": ["pick 1: dropped"]},
            {"params": {"part_mass": [0.1, 0.2], "holdable": [True, True]},
             "picks": [{"placed": True}, {"placed": False}], "reasons": ["pick 1: dropped"]},
            {"params": {"part_mass": [0.1, 0.2], "holdable": [True, True]}, "error": "boom", "ok": False}]
    assert holdable_counts(rows) == {"cannot_be_held": 1, "pick_success_rate_holdable": 2 / 5}
    summary = robust_summary(rows)
    assert summary["pick_success_rate"] == 2 / 6 and summary["cannot_be_held"] == 1
    assert holdable_counts([{"params": {"part_mass": [0.1]}}]) == {}  # a study from before the judgement
