"""A pick and place that sees its part through a rendered RGB-D camera (issue 34)."""

import numpy as np
import pytest
from conftest import run_cached

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.systems.perception import part_pose_estimator


def test_conveyor_pick_place_rgbd_places_a_randomly_placed_part_from_depth_images():
    result = run_cached("conveyor_pick_place_rgbd")
    (pick,) = result.metrics["picks"]
    assert result.ok, result.metrics.get("reasons")
    assert pick["placed"] and pick["seen"]
    assert pick["place_error_mm"] <= 3.0 and pick["place_error_deg"] <= 3.0
    assert pick["estimate_error_mm"] <= 3.0 and pick["estimate_error_deg"] <= 3.0


@pytest.mark.slow
def test_a_part_never_seen_is_not_grasped():
    # the perception looks for parts on a belt 0.3 m beside the real one: nothing is ever fitted
    elsewhere = ("measurement: {camera: {belts: [{center: [0.6, 0.0, 0.135], direction: [0.0, 1.0, 0.0], "
                 "length: 1.2, width: 0.09}]}}")
    result = run_cached("conveyor_pick_place_rgbd", elsewhere)
    (pick,) = result.metrics["picks"]
    assert not result.ok
    assert not pick["seen"] and not pick["grasped"]
    assert all(d["peak_grip_force_N"] == 0.0 for d in pick["attempt_details"])
    assert result.metrics["reasons"] == ["pick 0: part not seen"]


def test_a_part_fitted_twice_is_not_grasped(monkeypatch):
    """Two fits give the estimate no velocity to aim with: no grasp, ``pick 0: part not seen``
    (robust assembly_pick_place_rgbd sample 39: fitted once, grasped 107 mm behind the part)."""
    from ptint_drake.worlds.pick.camera import MIN_FITS

    real, frames = part_pose_estimator.fit_parts, []

    def twice(*args, **kwargs):  # the first two frames with a good fit, then nothing
        fits = real(*args, **kwargs)
        if any(f.ok for f in fits):
            frames.append(1)
        return fits if len(frames) <= 2 else []

    monkeypatch.setattr(part_pose_estimator, "fit_parts", twice)
    result = simulate(load_scenario("conveyor_pick_place_rgbd"))
    (pick,) = result.metrics["picks"]
    assert MIN_FITS == 3 and len(frames) > 2
    assert result.metrics["reasons"] == ["pick 0: part not seen"]
    assert not pick["grasped"] and all(d["peak_grip_force_N"] == 0.0 for d in pick["attempt_details"])


@pytest.mark.slow
def test_a_fit_forced_wrong_makes_the_pick_fail(monkeypatch):
    real = part_pose_estimator.fit_parts

    def shifted(*args, **kwargs):  # every fit 12 mm off along the pads (the part's y)
        fits = real(*args, **kwargs)
        for f in fits:
            f.position = f.position + np.array([0.012, 0.0, 0.0])
        return fits

    monkeypatch.setattr(part_pose_estimator, "fit_parts", shifted)
    result = simulate(load_scenario("conveyor_pick_place_rgbd"))
    (pick,) = result.metrics["picks"]
    assert not result.ok and not pick["placed"]
    assert pick["estimate_error_mm"] > 10.0


def test_e_true_is_against_the_simulated_part_and_e_estimate_against_the_estimate():
    result = run_cached("conveyor_pick_place_rgbd")
    series, (pick,) = result.series, result.metrics["picks"]
    j = int(np.argmin(np.abs(series["t"] - pick["t_grasp_prescribed"])))
    # the two targets differ at the grasp by the estimate's error, nothing else
    np.testing.assert_allclose(series["target"][j, 0:3] - series["target_true"][j, 0:3],
                               series["part_estimate_0"][j, 0:3] - series["part_true_0"][j, 0:3], atol=1e-9)
    np.testing.assert_allclose(series["e_true"], series["x"] - series["target_true"][:, 0:3])
    np.testing.assert_allclose(series["e_estimate"], series["x"] - series["target"][:, 0:3])
    gap = 1e3 * np.linalg.norm(series["e_true"][j] - series["e_estimate"][j])
    assert gap > 0.1  # the estimate is not the truth (1.65 mm off on this seed)
    assert abs(gap - pick["estimate_error_mm"]) < 0.05
