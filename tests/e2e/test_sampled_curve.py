"""Sampled control at 1 kHz (``controller.control_period``) keeps the paper's curve
(curve_b075_tf15) within the criteria, on the continuous plant and on Drake's discrete 1 ms
plant (``multibody``); one run each."""

import numpy as np
import pytest
from conftest import assert_prescribed_time, run_cached

CASES = {"continuous plant": "controller: {control_period: 0.001}",
         "discrete 1 ms plant": "controller: {control_period: 0.001}\nmultibody: {time_step: 0.001}"}


@pytest.mark.both_ends
@pytest.mark.parametrize("plant", CASES)
def test_1_khz_sampled_control_keeps_the_paper_curve_within_1_mm(plant):
    result = run_cached("curve_b075_tf15", CASES[plant])
    m = result.metrics
    assert m["status"] == "ok", m["reasons"]
    assert_prescribed_time(m, plant)
    seg = m["segments"][0]
    assert seg["e_tf_norm"] <= 0.2e-3 and seg["e_hold_max_norm"] <= 0.5e-3  # measured 0.05-0.07, 0.12-0.13 mm
    assert m["sim"]["control_period"] == 0.001
    assert m["sim"]["plant_time_step"] == (0.001 if "discrete" in plant else 0.0)
    tau = result.series["tau"]  # the held torque (tests/unit/test_sampled.py)
    assert np.max(np.abs(tau), axis=0)[1] < 8.0  # no chattering (joint 2's continuous peak: 6.0 N·m)
