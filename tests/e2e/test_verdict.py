"""A run says plainly whether it intercepted: exit codes, MISSED lines, warnings, honest peaks.

``ptint run`` in this process (``ptint_here``): what it prints and its exit code are the
command's; test_cli.py keeps a real subprocess run."""

import contextlib
import io
import json

from ptint_drake.verdict.metrics import Criteria, Reason, verdict


def ptint_one_stream(*args) -> tuple[int, list[str]]:
    """``ptint ARGS`` in this process: its exit code and what it printed to stdout and stderr as
    one list of lines, in the order printed (as a terminal shows them).  The simulation must run
    in this process (``--no-figures``: no forked simulation, whose prints would not be seen)."""
    from ptint_drake import cli  # noqa: PLC0415

    stream = io.StringIO()
    with contextlib.redirect_stdout(stream), contextlib.redirect_stderr(stream):
        code = cli.main([str(a) for a in args])
    return code, stream.getvalue().splitlines()


def test_a_tf_the_actuators_cannot_do_is_a_miss(tmp_path):
    code, lines = ptint_one_stream("run", "curve_b075_tf15", "--set", "interceptions[0].tf=0.03",
                                   "--out", tmp_path, "--quiet", "--no-replay", "--no-figures")
    text = "\n".join(lines)
    assert code == 1, text
    segment = [i for i, line in enumerate(lines) if line.startswith("curve_b075_tf15 segment 0:")]
    assert len(segment) == 1 and "MISSED (late" in lines[segment[0]], text
    assert "ptint tune" in lines[-1], text
    # the run opens with what it runs; the feasibility warning (known before the simulation) is
    # printed once, after that line and before every other line of the run's own (segment
    # line, realtime factor, verdict) ...
    assert lines[0].startswith("running curve_b075_tf15: the interception world, 3 s simulated, "
                               "controller ptsmc"), text
    feasibility = [i for i, line in enumerate(lines) if "looks too short for the actuators" in line]
    assert len(feasibility) == 1, text
    assert lines[feasibility[0]].startswith("ptint: warning: interceptions[0].tf = 0.03 s"), text
    own = [i for i, line in enumerate(lines[1:], start=1) if not line.startswith("ptint: warning: ")]
    assert feasibility[0] < min(own), text
    # ... and the warnings known only after it (joint speeds beyond the model's) after its lines
    realtime = [i for i, line in enumerate(lines) if line.startswith("realtime factor ")]
    speed = [i for i, line in enumerate(lines) if "beyond the model's limit" in line]
    assert len(realtime) == 1 and speed and segment[0] < realtime[0] < min(speed), text
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["status"] == "missed" and "segment 0: late" in m["reasons"]
    assert m["segments"][0]["tf"] == 0.03


def test_a_pose_the_wrist_cannot_turn_in_time_misses_on_orientation(tmp_path, ptint_here):
    """curve_pose with tf = 0.2 s (1.5 s bundled): the actuators saturate and the tool's 76° turn
    is still ≈ 24° away at tf, far beyond the 2° bound, while its position is within about a
    millimetre: the verdict's reasons name ``orientation`` on segment 0, and it is the angle
    against the angle's bounds that decides it."""
    out = ptint_here("run", "curve_pose", "--set", "interceptions[0].tf=0.2", "--set", "duration=0.6",
                     "--out", tmp_path, "--quiet", "--no-replay", "--no-figures")
    assert out.returncode == 1, out.stderr
    m = json.loads((tmp_path / "metrics.json").read_text())
    seg, criteria = m["segments"][0], Criteria(**m["criteria"])
    assert (criteria.e_rot_tf_deg, criteria.rot_hold_deg) == (2.0, 5.0)  # the defaults: no override
    assert m["status"] == "missed"
    assert {"segment": 0, "code": "orientation"} in m["reason_codes"]
    assert "segment 0: orientation" in m["reasons"]
    assert seg["e_rot0_deg"] > 45.0 and seg["e_rot_tf_deg"] > 5 * criteria.e_rot_tf_deg
    assert seg["e_rot_hold_max_deg"] > criteria.rot_hold_deg
    line = next(line for line in out.stdout.splitlines() if line.startswith("curve_pose segment 0:"))
    assert f"/ {seg['e_rot_tf_deg']:.3g}°, hold max = " in line, line  # e(tf): mm / angle
    assert line.endswith(")") and "orientation" in line.rsplit("MISSED (", 1)[1], line
    # the angle decides: bounds that cover its angles drop ``orientation`` and nothing else ...
    loose = Criteria(**m["criteria"] | {"e_rot_tf_deg": 2 * seg["e_rot_tf_deg"],
                                        "rot_hold_deg": 2 * seg["e_rot_hold_max_deg"]})
    others = [Reason.from_dict(r) for r in m["reason_codes"] if r["code"] != "orientation"]
    assert verdict(m, loose)[1] == others
    # ... and with the position bounds loosened instead, orientation alone makes it a miss
    position_loose = Criteria(**m["criteria"] | {"e_tf": 1.0, "hold": 1.0})
    assert verdict(m, position_loose) == ("missed", [Reason(0, "orientation")])


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
