"""A run says plainly whether it intercepted: exit codes, MISSED lines, warnings, honest peaks.

``ptint run`` in this process (``ptint_here``): what it prints and its exit code are the
command's; test_cli.py keeps a real subprocess run."""

import json


def test_a_tf_the_actuators_cannot_do_is_a_miss(tmp_path, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--set", "interceptions[0].tf=0.03", "--out", str(tmp_path),
                "--quiet", "--no-replay", "--no-figures")
    assert out.returncode == 1, out.stderr
    assert "curve_b075_tf15 segment 0:" in out.stdout and "MISSED (late" in out.stdout
    assert "ptint tune" in out.stdout
    # the feasibility warning comes before the run's own lines
    warning = out.stderr.index("looks too short for the actuators")
    assert warning >= 0
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["status"] == "missed" and "segment 0: late" in m["reasons"]
    assert m["segments"][0]["tf"] == 0.03


def test_the_paper_run_is_ok_and_exits_0(tmp_path, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--out", str(tmp_path), "--quiet", "--no-replay",
                     "--no-figures")
    assert out.returncode == 0, out.stderr
    assert out.stdout.rstrip().endswith("ok (every segment meets the criteria)")
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["status"] == "ok" and m["reasons"] == []
    # peaks come with their times, and the peak after start-up leaves the first 5 % of tf out
    assert len(m["torque_peak_time"]) == 3 and all(0 <= t <= 3.0 for t in m["torque_peak_time"])
    assert all(t >= 0.05 * 1.5 for t in m["torque_peak_after_startup_time"])
    assert all(a <= b + 1e-12 for a, b in zip(m["torque_peak_after_startup"], m["torque_peak"]))
    # the realtime factor is end to end, the simulation-only figure beside it
    assert m["sim"]["realtime_factor"] <= m["sim"]["simulation_realtime_factor"]


def test_assembly_warns_about_joint_speeds_beyond_the_model(tmp_path, ptint_here):
    out = ptint_here("run", "assembly", "--out", str(tmp_path), "--quiet", "--no-replay", "--no-figures")
    assert out.returncode == 0, out.stderr
    speed = [line for line in out.stderr.splitlines()
             if "speed" in line and "beyond the model's limit 3" in line]
    assert speed, out.stderr
    assert speed[0].startswith("ptint: warning: joint ") and " at t = " in speed[0]
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert len(m["joint_speed_peak"]) == 3 and max(m["joint_speed_peak"]) > 3.0
    assert any("beyond the model's limit" in w for w in m["warnings"])
