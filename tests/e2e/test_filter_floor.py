"""The filter-only error floor (``ptint study camera --filter-floor``): camera + Kalman filter
without an arm, measured against the true objects."""

import json

import numpy as np
import pytest

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, parse_scenario, scenario_text
from ptint_drake.studies import filter_floor as floor

NAME, TEXT = scenario_text("curve_camera")
LOADED = LoadedScenario.parse(TEXT, NAME)
SEEDS = 6


@pytest.fixture(scope="module")
def curve_2mm():
    return floor.filter_floor(LOADED, [0.03], SEEDS, workers=1)


def test_noiseless_camera_on_a_constant_velocity_belt_has_no_floor():
    belt = LoadedScenario.load("conveyor_pair_camera")
    result = floor.filter_floor(belt, [1e-6], 2, measurement={"noise_std": 0.0, "latency": 0.0,
                                                               "estimator": "kalman_cv"}, workers=1)
    assert [row["estimator"] for row in result["table"]] == ["auto", "kalman_cv"]
    for row in result["table"]:
        s = row["summary"]
        assert s["errors"] == 0 and s["runs"] == 2
        assert s["hold_max_worst"] < 1e-5, row["estimator"]
    for run in result["runs"]:
        assert len(run["segments"]) == 2
        assert run["run_max"] < 1e-5  # the selector's output over the whole run too
        assert [seg["hold_from"] for seg in run["segments"]] == [0.9, 2.2]
        assert [seg["hold_to"] for seg in run["segments"]] == [1.2, 3.0]
        # read far more densely than the camera's 30 Hz (at least 240 Hz)
        assert all(seg["samples"] >= 240 * (seg["hold_to"] - seg["hold_from"]) for seg in run["segments"])
    # the same belt with the scenario's 2 mm noise is far from exact: the check above can fail
    noisy = floor.floor_case(belt.text, belt.name, {"estimator": "kalman_cv", "process_noise": 1e-6}, 1)
    assert noisy["segments"][0]["hold_max"] > 1e-4


@pytest.mark.slow
def test_less_noise_lowers_the_floor(curve_2mm):
    one_mm = floor.filter_floor(LOADED, [0.03], SEEDS, measurement={"noise_std": 0.001}, workers=1)
    assert one_mm["measurement"]["noise_std"] == 0.001
    for row in (0, 1):  # auto, and kalman_ca q = 0.03
        low, high = one_mm["table"][row]["summary"], curve_2mm["table"][row]["summary"]
        assert low["hold_max_median"] < high["hold_max_median"]
        assert low["run_rms_median"] < high["run_rms_median"]


def test_curve_camera_floor_is_near_6_mm(curve_2mm):
    """2 mm / 30 Hz / 33 ms, kalman_ca q = 0.03: a scratch per-axis filter gave a median of
    about 6 mm for the largest error over [1.5, 3] s; the project's systems must agree."""
    s = curve_2mm["table"][1]["summary"]
    assert curve_2mm["table"][1]["estimator"] == "kalman_ca"
    assert s["errors"] == 0 and s["runs"] == SEEDS
    assert 4e-3 <= s["hold_max_median"] <= 8e-3
    assert s["hold_max_p90"] >= s["hold_max_median"]
    assert curve_2mm["best"]["process_noise"] == 0.03
    assert [r["seed"] for r in curve_2mm["runs"]] == list(range(1, SEEDS + 1)) * 2


def test_auto_follows_the_curve_better_than_the_best_hand_set_filter(curve_2mm):
    """The turn model of ``auto`` fits the paper's ellipse: its floor is below kalman_ca's."""
    auto, hand = (curve_2mm["table"][i]["summary"] for i in (0, 1))
    assert curve_2mm["table"][0]["estimator"] == "auto"
    assert auto["hold_max_median"] < 0.8 * hand["hold_max_median"]


def test_floor_is_what_the_closed_loop_controller_sees(curve_2mm):
    """Same systems, same seed: the target logged in the closed loop (the filter's output)
    is as far from the truth over the hold as the floor says."""
    scenario = parse_scenario(TEXT, NAME)
    scenario.measurement.seed = 1
    series = simulate(scenario, check=False).series
    t = series["t"]
    hold = (t >= 1.5) & (t <= 3.0)
    logged = np.linalg.norm(series["x_r"][hold] - series["objects"][hold, 0:3], axis=1).max()
    floor = curve_2mm["runs"][0]["segments"][0]["hold_max"]
    assert curve_2mm["runs"][0]["seed"] == scenario.measurement.seed == 1
    assert floor == pytest.approx(logged, abs=0.1e-3)


def test_bad_arguments_name_the_field():
    with pytest.raises(ScenarioError, match=r"^process_noise: "):
        floor.filter_floor(LOADED, [0.03, 0.0], 1, workers=1)
    with pytest.raises(ScenarioError, match=r"^measurement: "):
        floor.filter_floor(LoadedScenario.load("curve_b075_tf15"), [0.03], 1, workers=1)
    with pytest.raises(ScenarioError, match=r"^measurement\.noise_std: "):
        floor.filter_floor(LOADED, [0.03], 1, measurement={"noise_std": -1.0}, workers=1)


@pytest.mark.parametrize("args, message", [
    (["--process-noise", "0.03,-0.1"],
     "ptint: error: --process-noise: every value must be > 0 and finite, got -0.1"),
    (["--scenario", "curve_b075_tf15"], "ptint: error: measurement: the filter floor needs a camera "
                                        "scenario, curve_b075_tf15 has no camera"),
])
def test_cli_bad_value_is_one_line_exit_2(tmp_path, args, message, ptint_here):
    out = ptint_here("study", "camera", "--filter-floor", *args, "--out", str(tmp_path / "o"), "--quiet")
    assert out.returncode == 2, out.stderr
    assert "Traceback" not in out.stderr
    assert [line for line in out.stderr.splitlines() if line.strip()] == [message]
    assert not (tmp_path / "o").exists()


def test_cli_writes_json_and_markdown(tmp_path, ptint_here):
    out = ptint_here("study", "camera", "--filter-floor", "--seeds", "2", "--process-noise", "0.03",
                "--set", "measurement.noise_std=0.001", "--workers", "1", "--out", str(tmp_path), "--quiet")
    assert out.returncode == 0, out.stderr
    assert len(out.stdout.splitlines()) == 1 and "best kalman_ca q = 0.03" in out.stdout
    assert "auto hold max median" in out.stdout
    result = json.loads((tmp_path / "filter_floor.json").read_text())
    assert result["measurement"]["noise_std"] == 0.001 and result["seeds"] == 2
    md = (tmp_path / "filter_floor.md").read_text()
    median = result["table"][1]["summary"]["hold_max_median"]
    assert f"| kalman_ca | 0.03 | {median * 1e3:.2f} |" in md
    assert f"| auto |  | {result['table'][0]['summary']['hold_max_median'] * 1e3:.2f} |" in md
