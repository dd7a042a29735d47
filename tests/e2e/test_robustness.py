"""Issue: robust and safe — disturbances, measurement, limits, singularities, divergence, outputs."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import TOO_SHORT_TF, assert_prescribed_time, run_cached, sigint_default

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import parse_scenario, scenario_text
from ptint_drake.studies.robust import RANGES, sample_scenario
from ptint_drake.systems.perception.camera import MeasurementConfig
from ptint_drake.worlds.interception.disturbance import JointDisturbance
from ptint_drake.worlds.registry import objects_of

HERE = Path(__file__).parent
NAME, TEXT = scenario_text("curve_b075_tf15")


def ptint(*args, **kw):
    return subprocess.run([sys.executable, "-m", "ptint_drake", *args], capture_output=True,
                          text=True, timeout=900, cwd=HERE, **kw)


def test_disturbance_law():
    d = JointDisturbance(3, 3, amplitude=[1, 0, 0], frequency_hz=2.0, step=[0, 2, 0], step_time=0.5,
                         coulomb=[0, 0, 0.3], coulomb_speed=0.01)
    np.testing.assert_allclose(d.torque(0.125, np.array([0, 0, 1.0])),
                               [np.sin(2 * np.pi * 2 * 0.125), 0, -0.3 * np.tanh(100)])
    np.testing.assert_allclose(d.torque(0.6, np.zeros(3)), [np.sin(2 * np.pi * 2 * 0.6), 2, 0])
    context = d.CreateDefaultContext()  # the C++ (symbolic) system computes the same law
    for t, v in ((0.125, [0, 0, 1.0]), (0.5, [0, 0, -0.002]), (0.6, [0, 0, 0.001])):
        context.SetTime(t)
        d.get_input_port().FixValue(context, np.r_[np.zeros(3), v])
        np.testing.assert_allclose(d.get_output_port().Eval(context), d.torque(t, np.array(v)),
                                   rtol=1e-14, atol=1e-15)
    with pytest.raises(ValueError, match="one value per joint"):
        JointDisturbance(3, 3, amplitude=[1, 2])


def test_metrics_use_the_true_target():
    """20 ms of uncompensated latency of a noiseless camera on a 0.15 m/s target: the controller
    converges on the delayed image (its own e(tf) small) but really misses by |ẋ_r| L ≈ 3 mm."""
    scenario = parse_scenario(TEXT, NAME)
    scenario.measurement = MeasurementConfig(latency=0.02, compensate_latency=False)
    result = simulate(scenario)
    seg = result.metrics["segments"][0]
    k = np.argmin(np.abs(result.series["t"] - 1.5))
    assert np.linalg.norm(result.series["e"][k]) < 1.5e-3  # what the controller sees
    speed = np.linalg.norm(objects_of(parse_scenario(TEXT, NAME))[0].evaluate(1.5)[3:6])
    assert seg["e_tf_norm"] == pytest.approx(speed * 0.02, rel=0.05)  # ≈ 3.5 mm
    scenario.measurement.compensate_latency = True
    assert simulate(scenario).metrics["segments"][0]["e_tf_norm"] < 1e-3


def test_payload_and_friction_reach_the_plant():
    base = run_cached("curve_b075_tf15")
    loaded = run_cached("curve_b075_tf15", "plant: {payload_kg: 0.5, coulomb: [0.3, 0.3, 0.3]}")
    assert_prescribed_time(loaded.metrics, "payload 0.5 kg + Coulomb 0.3 N·m")
    # holding 0.5 kg about 0.2 m out needs ~1 N·m more at the shoulder
    assert loaded.metrics["torque_peak"][1] > base.metrics["torque_peak"][1] + 0.5


@pytest.mark.slow
def test_robust_study_and_exact_replay_of_worst_seed(tmp_path, ptint_here):
    """Both commands in this process (``ptint_here``)."""
    out = ptint_here("robust", "curve_b075_tf15", "--samples", "6", "--seed", "11", "--workers", "2",
                "--out", str(tmp_path), "--quiet")
    assert out.returncode == 0, out.stderr
    summary = json.loads((tmp_path / "robust.json").read_text())
    assert summary["samples"] == 6 and summary["success_rate"] == 1.0
    for key in ("p50", "p90", "p99", "max"):
        assert summary["e_tf_percentiles"][key] < 1e-3
        assert summary["torque_peak_percentiles"][key] > 0
    assert (tmp_path / "robust.png").stat().st_size > 10_000
    worst = summary["worst"]
    assert 11 <= worst["seed"] < 17
    # the worst sample replays exactly from its file, and from its seed
    replay = ptint_here("run", str(tmp_path / "worst.yaml"), "--out", str(tmp_path / "replay"), "--quiet",
                   "--no-replay", "--no-figures")
    assert replay.returncode == 0, replay.stderr
    metrics = json.loads((tmp_path / "replay" / "metrics.json").read_text())
    assert metrics["segments"][0]["e_tf_norm"] == worst["e_tf"][0]
    scenario, params = sample_scenario(TEXT, NAME, worst["seed"])
    assert params == worst["params"]
    assert RANGES["mass"][0] <= params["mass_scale"] <= RANGES["mass"][1]


def test_too_short_tf_warns_and_saturates_but_stays_stable(tmp_path, ptint_here):
    scenario = tmp_path / "short.yaml"
    scenario.write_text(TOO_SHORT_TF)
    out = ptint_here("run", str(scenario), "--out", str(tmp_path / "out"), "--quiet", "--no-replay",
                "--no-figures")
    assert out.returncode == 1, out.stderr  # a miss: exit 1
    assert "MISSED (late, hold)" in out.stdout and "ptint tune" in out.stdout
    warning = [line for line in out.stderr.splitlines() if line.startswith("ptint: warning:")]
    assert warning and "interceptions[0].tf = 0.2 s looks too short" in warning[0]
    assert "tf ≥" in warning[0] and "would fit" in warning[0]
    m = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert m["status"] == "missed" and m["reasons"] == ["segment 0: late", "segment 0: hold"]
    assert m["saturated_fraction"] > 0.05
    assert all(p <= lim + 1e-9 for p, lim in zip(m["torque_peak"], m["effort_limits"]))
    series = np.load(tmp_path / "out" / "series.npz")
    assert np.all(np.isfinite(series["q"])) and np.max(np.abs(series["v"])) < 50


SINGULAR = """duration: 1.6
robot: {model: rvm1, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0]}
controller: {pinv_damping: DAMPING}
interceptions:
  - {start: 0.0, tf: 0.8, beta: 0.75, target: {linear: {start: [0.1, 0.0, 0.45], velocity: [-0.1, 0.0, 0.0]}}}
"""


@pytest.mark.parametrize("damping", [0.0, 0.01])
def test_target_through_a_singularity(damping):
    """The target crosses the waist axis (x = y = 0) at t = 1.0 s: J loses rank there."""
    result = simulate(parse_scenario(SINGULAR.replace("DAMPING", str(damping)), "singular"))
    m = result.metrics
    assert m["status"] == "ok"
    assert np.all(np.isfinite(result.series["tau"]))
    assert any("near-singular Jacobian" in w and "t = 1.00" in w for w in m["warnings"]), m["warnings"]
    assert_prescribed_time(m, "through the waist axis")
    if damping:  # the damped pseudoinverse keeps the commanded torque small
        assert max(m["torque_command_peak"]) < 10.0
    else:  # the exact inverse asks for huge torques there (clipped by the saturation)
        assert max(m["torque_command_peak"]) > 100.0


def test_forced_divergence_is_reported_and_kept(tmp_path, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet", "--no-replay",
                "--set", "plant.disturbance={step: [0, 500, 0], step_time: 0.5}")
    assert out.returncode == 1
    assert "diverged at t = 0.5" in out.stderr and "joint speed" in out.stderr
    assert "Traceback" not in out.stderr
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["status"] == "failed" and "joint speed" in m["failure"]["message"]
    assert 0.5 <= m["failure"]["time"] < 0.7
    assert m["segments"][0]["e0_norm"] > 0 and m["segments"][0]["e_tf_norm"] is None
    series = np.load(tmp_path / "series.npz")  # what was computed until then is kept
    assert series["t"][-1] == pytest.approx(m["failure"]["time"], abs=1e-9)
    assert (tmp_path / "errors.png").is_file()


@pytest.mark.slow
def test_sigint_leaves_no_half_written_files(tmp_path):
    out_dir = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "ptint_drake", "paper", "--out", str(out_dir)],
                            cwd=HERE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=sigint_default)
    deadline = time.time() + 120
    while time.time() < deadline and not (out_dir / "curve_b025_tf15").exists() \
            and not list(out_dir.glob("curve_b025_tf15*")):
        staged = list(out_dir.glob("*/.ptint-stage-*")) + list(out_dir.glob(".ptint-stage-*"))
        if staged:
            break
        time.sleep(0.05)
    time.sleep(0.3)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert not list(out_dir.rglob(".ptint-stage-*"))
    assert not (out_dir / "index.html").exists()
    for metrics in out_dir.rglob("metrics.json"):  # any run that finished is complete
        run = metrics.parent
        assert (run / "series.npz").is_file() and (run / "replay.html").is_file()


@pytest.mark.slow
def test_second_run_does_not_mix_with_the_first(tmp_path, ptint_here):
    """The first run (0.6 s of it: its files are the point, not its length) writes a replay and
    figures as a real command (a replay drawn in this process would leave a Meshcat here)."""
    assert ptint("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet", "--set", "duration=0.6",
                 "--set", "interceptions[0].tf=0.5").returncode == 0
    assert (tmp_path / "replay.html").is_file() and (tmp_path / "axes.png").is_file()
    assert ptint_here("run", "curve_b050_tf15", "--out", str(tmp_path), "--quiet", "--no-replay",
                 "--no-figures").returncode == 0
    assert not (tmp_path / "replay.html").exists() and not (tmp_path / "axes.png").exists()
    assert json.loads((tmp_path / "metrics.json").read_text())["scenario"] == "curve_b050_tf15"
    assert sorted(p.name for p in tmp_path.iterdir()) == [".ptint-manifest.json", "metrics.json",
                                                          "series.npz"]
