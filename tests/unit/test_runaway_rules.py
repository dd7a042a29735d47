"""The runaway tests of a pick (``worlds.pick.runaway``) and the feasibility warning's form
(``run_warnings.feasibility_warning``); the real runs are in tests/e2e/test_pick_runaway.py."""

from types import SimpleNamespace

import numpy as np

from ptint_drake.verdict.run_warnings import Profile, feasibility_warning
from ptint_drake.worlds.pick.collisions import touched_before_close
from ptint_drake.worlds.pick.runaway import SATURATED_FRACTION, SPEED_RUNAWAY_S, runaway_reasons


def test_the_thresholds_name_a_runaway_and_nothing_below_them():
    # rvm1_6dof's wrist flipping by its singularity for 156 ms beyond 3 times its limit: no runaway
    flip = {"saturated_fraction": 0.156, "joint_speed_ratio": 5.18, "joint_speed_over_s": 0.156}
    assert runaway_reasons(flip) == []
    at = {"saturated_fraction": SATURATED_FRACTION, "joint_speed_over_s": SPEED_RUNAWAY_S}
    assert runaway_reasons(at) == ["saturated", "joint speed beyond limit"]
    assert runaway_reasons({"saturated_fraction": 0.49, "joint_speed_over_s": 0.29}) == []
    assert runaway_reasons({}) == []  # metrics of before issue 44


def test_the_feasibility_warning_names_the_field_the_joint_and_the_ratio():
    profile = Profile(np.array([1.0, 1.1]), np.zeros((2, 2)), np.zeros((2, 3)), np.zeros((2, 3)))
    limits = np.array([3.0, 4.0])
    fits = np.array([[1.0, 1.0], [2.9, 3.9]])
    field, what = "pick.tasks[0].approach.tf", "pick 0's approach (segment 0)"
    assert feasibility_warning(field, 1.2, what, profile, fits, fits, limits, limits) is None
    line = feasibility_warning(field, 0.3, what, profile, np.array([[1.0, 1.0], [9.0, 2.0]]),
                               np.array([[0.0, 0.0], [6.0, 1.0]]), limits, limits)
    assert line == ("pick.tasks[0].approach.tf = 0.3 s looks too short for the joints: pick 0's approach "
                    "(segment 0) needs joint 1 at 3.00× its speed limit (9 rad/s against 3 rad/s) at "
                    "t = 1.10 s, its torque 2.00×; pick.tasks[0].approach.tf ≥ about 0.90 s would fit")


def test_what_the_open_fingers_touch_before_the_close_is_named_own_part_included():
    built = SimpleNamespace(station=SimpleNamespace(obstacles=["belt", "tray", "floor", "part"]))
    flags = np.zeros((4, 8))
    flags[1, 2 * 3] = 1.0  # a finger on the own part
    flags[3, 2 * 1 + 1] = 1.0  # an arm link on the tray, after the close
    before = np.array([True, True, False, False])
    assert touched_before_close(built, {"collisions": (np.arange(4.0), flags)}, before) == ["part"]
    assert touched_before_close(built, {}, before) == []
