"""The ptint command line (SPEC section 5): list, run outputs, and bad input."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ptint_drake.simulation.scenario import scenario_text

PAPER = ["assembly", "curve_b025_tf15", "curve_b050_tf15", "curve_b075_tf12", "curve_b075_tf15",
         "curve_b075_tf19"]


def ptint(*args):
    """Run the installed command (from a neutral folder, so the source tree is not imported)."""
    return subprocess.run([sys.executable, "-m", "ptint_drake", *args], capture_output=True,
                          text=True, cwd=Path(__file__).parent, timeout=600)


def test_list_names_every_paper_scenario(ptint_here):
    """In this process (test_cli_hygiene.py pipes the real command into head)."""
    out = ptint_here("list")
    assert out.returncode == 0
    names = [line.split()[0] for line in out.stdout.splitlines()]
    assert set(PAPER) <= set(names)


@pytest.mark.both_ends
def test_run_writes_spec_outputs(tmp_path):
    out = ptint("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet")
    assert out.returncode == 0, out.stderr
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["scenario"] == "curve_b075_tf15" and m["duration"] == 3.0
    seg = m["segments"][0]
    for key in ("start", "tf", "beta", "e0_norm", "e_half_norm", "e_tf_norm", "edot_tf_norm",
                "e_hold_max_norm"):
        assert key in seg
    assert seg["e_tf_norm"] < 1e-3
    assert len(m["torque_peak"]) == 3
    for key in ("integration_scheme", "accuracy", "wall_time_s", "realtime_factor", "steps",
                "derivative_evaluations"):
        assert key in m["sim"]
    series = np.load(tmp_path / "series.npz")
    for key in ("t", "q", "v", "tau", "x", "x_r", "e", "edot", "xi", "alpha", "s_x"):
        assert key in series
    # the metric at tf is the state at exactly tf (a logged step ends there)
    k = np.argmin(np.abs(series["t"] - 1.5))
    assert series["t"][k] == pytest.approx(1.5, abs=1e-12)
    assert np.linalg.norm(series["e"][k]) == pytest.approx(seg["e_tf_norm"], rel=1e-9)
    html = (tmp_path / "replay.html").read_text()
    assert html.startswith("<!DOCTYPE html>") or "<html" in html[:500]
    assert len(html) > 1_000_000  # self-contained: meshcat's JS is inlined
    for fig in m["figures"]:
        assert (tmp_path / fig).stat().st_size > 10_000
    # PNG figures only without --svg (test_visuals.py: the SVGs with the flag)
    assert {p.stem for p in tmp_path.glob("*.png")} >= {"axes", "errors", "joints", "paths3d"}
    assert not list(tmp_path.glob("*.svg"))
    assert not list(tmp_path.glob(".ptint-stage-*"))


def test_set_overrides_a_field(tmp_path, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet", "--no-replay",
                "--no-figures", "--set", "interceptions=[{start: 0, tf: 1.0, beta: 0.5, target: "
                "{linear: {start: [0.25, 0.05, 0.3], velocity: [0, 0.05, 0]}}}]", "--set", "duration=1.5")
    assert out.returncode == 0, out.stderr
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["duration"] == 1.5 and m["segments"][0]["tf"] == 1.0 and m["segments"][0]["beta"] == 0.5


BASE = scenario_text("curve_b075_tf15")[1]
LINEAR2 = """interceptions:
  - {start: 0.0, tf: 1.0, beta: 0.75, target: {linear: {start: [0.3, -0.15, 0.15], velocity: [0, 0.1, 0]}}}
  - {start: START2, tf: 1.0, beta: 0.75, target: {linear: {start: [0.2, -0.2, 0.25], velocity: [0, 0.1, 0]}}}
"""
BAD = {
    "beta_high": (BASE.replace("beta: 0.75", "beta: 1.0"), "interceptions[0].beta"),
    "beta_zero": (BASE.replace("beta: 0.75", "beta: 0.0"), "interceptions[0].beta"),
    "tf_zero": (BASE.replace("tf: 1.5", "tf: 0.0"), "interceptions[0].tf"),
    "tf_negative": (BASE.replace("tf: 1.5", "tf: -1.0"), "interceptions[0].tf"),
    "duration": (BASE.replace("duration: 3.0", "duration: 0"), "duration"),
    "unknown_key": (BASE + "\nfoo: 1\n", "foo"),
    "unknown_nested": (BASE.replace("alpha_hold: 0.0", "alpha_hold: 0.0, gain: 2"), "controller.gain"),
    "vector_length": (BASE.replace("amplitude: [0.1, 0.1, 0.1]", "amplitude: [0.1, 0.1]"),
                      "interceptions[0].target.sinusoid.amplitude"),
    "q_length": (BASE.replace("[22.5, 45.0, 30.0]", "[22.5, 45.0]"), "robot.initial_q_deg"),
    "two_targets": (BASE.replace("    target:\n", "    target:\n      linear: {start: [0.3, 0, 0.2], "
                                 "velocity: [0, 0, 0]}\n"), "interceptions[0].target"),
    "no_target": (BASE.replace("      sinusoid:", "      sinusoidx:"), "sinusoidx"),
    "overlap": (BASE.split("interceptions:")[0] + LINEAR2.replace("START2", "0.5")
                + "simulator: {accuracy: 1.0e-4}\n", "interceptions[1].start"),
    "unordered": (BASE.split("interceptions:")[0] + LINEAR2.replace("START2", "-1.0")
                  + "simulator: {accuracy: 1.0e-4}\n", "interceptions[1].start"),
    "unreachable": (BASE.replace("center: [0.24, 0.0, 0.3]", "center: [0.9, 0.0, 0.3]"),
                    "interceptions[0].target"),
    "missing_model": (BASE.replace("model: rvm1", "model: /nonexistent/robot.urdf"), "robot.model"),
    "missing_frame": (BASE.replace("end_effector: tool", "end_effector: gripper_tip"),
                      "robot.end_effector"),
    "malformed": (BASE + "\n  : [\n", "malformed"),
    "not_a_number": (BASE.replace("duration: 3.0", "duration: three"), "duration"),
    "bad_integrator": (BASE.replace("runge_kutta3", "rk99"), "simulator.integration_scheme"),
    "after_end": (BASE.replace("duration: 3.0", "duration: 1.0"), "interceptions[0].tf"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_input_fails_with_one_line(tmp_path, case, ptint_here):
    """In this process (``cli.main``); the subprocess tests below keep the process-level truth."""
    text, field = BAD[case]
    scenario = tmp_path / f"{case}.yaml"
    scenario.write_text(text)
    out_dir = tmp_path / "out"
    out = ptint_here("run", str(scenario), "--out", str(out_dir), "--quiet")
    assert out.returncode == 2
    assert "Traceback" not in out.stderr
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith("ptint: error: ") and field in lines[0], lines[0]
    assert not (out_dir / "metrics.json").exists()


def test_missing_scenario_name(ptint_here):
    out = ptint_here("run", "no_such_scenario", "--quiet")
    assert out.returncode == 2 and "scenario" in out.stderr and "Traceback" not in out.stderr


def test_failed_run_keeps_previous_complete_output(tmp_path, ptint_here):
    """A bad scenario into a folder with a complete run leaves that run intact."""
    ok = ptint_here("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet", "--no-replay",
               "--no-figures")
    assert ok.returncode == 0
    before = (tmp_path / "metrics.json").read_text()
    bad = tmp_path / "bad.yaml"
    bad.write_text(BAD["beta_high"][0])
    assert ptint_here("run", str(bad), "--out", str(tmp_path), "--quiet").returncode == 2
    assert (tmp_path / "metrics.json").read_text() == before
