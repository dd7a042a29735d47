"""The pick world's physics over 2 s (issue 20's tests): a part held against gravity by the
closed gripper stays put, and a part on a running belt moves with the belt — one hold experiment
(``pick.holding``: arm held by a joint PD, belt at 0.1 m/s, gripper closed with 30 N per finger)."""

from __future__ import annotations

import pytest

from ptint_drake.worlds.pick.config import BeltConfig, GripperConfig, PartConfig, PickWorldConfig
from ptint_drake.worlds.pick.holding import measure_hold


@pytest.fixture(scope="module")
def hold():
    config = PickWorldConfig(gripper=GripperConfig(initial_opening=0.031), belts=[BeltConfig()],
                             parts=[PartConfig(name="held"), PartConfig(name="riding", offset=-0.2)])
    return measure_hold(config, duration=2.0)


def test_held_part_stays_put(hold):
    assert hold["held_drift_mm"] <= 1.0
    assert hold["grip_force_N"] == pytest.approx([-30.0, -30.0], abs=0.5)  # squeezing at the force limit


def test_part_rides_its_belt(hold):
    assert hold["belt_speed_error_pct"] <= 3.0
