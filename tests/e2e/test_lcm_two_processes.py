"""The hardware path (issue 35): ``ptint hardware`` and ``ptint drive`` as two real processes
talking LCM inside a private network namespace with loopback alone (``tests/lcm_link/netns.py``;
without one the tests say so and the memq:// unit tests run the checks), one test per fault."""

from __future__ import annotations

import json
import os
import re
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cached
from lcm_link.netns import require_netns, run_in_netns

pytestmark = pytest.mark.e2e

HERE = Path(__file__).resolve().parents[1] / "lcm_link"
CURVE = "curve_b075_tf15"
PICK = "conveyor_pick_place"
RGBD_PICK = "conveyor_pick_place_rgbd"
PERIOD = 1e-3
# a process may take seconds to import pydrake and build its diagram when the suite loads both
# cores (CI): a patient start-up, except where the start-up timeout is what a test checks
PATIENT = ("--startup-timeout", "60")
# real time on the loaded 2-core virtual machine of CI: a process (or the machine's virtual CPU)
# may stall for several milliseconds (measured: sleeps overshooting by up to 8 ms at load 4.5 even
# under SCHED_FIFO; 20 ms once in the whole suite), so the real-time tests give a slack of 100
# periods (the kill test checks the reaction is exactly that); the default 5 is measured by
# scripts/link_faults.py and tests/unit/test_lcm_checks.py
SLACK = ("--silent-periods", "100")
# lockstep: the hardware's pace is the machine's, and a rendered tick of the camera's station
# took over the drive's default status timeout (0.5 s) once at load 12 (t = 0.09 s): not what
# the accuracy test checks
LOCKSTEP_DRIVE = ("--status-timeout", "30")


def ptint(*args: str) -> list[str]:
    return [sys.executable, "-m", "ptint_drake.cli", *args]


def run_plan(plan: list[dict], cwd: Path, timeout: float = 120.0) -> dict:
    """Each process of ``plan`` (``tests/lcm_link/pair.py``) inside one private namespace, in the
    folder ``cwd`` (a command's default out/ lands there)."""
    require_netns()
    done = run_in_netns([sys.executable, str(HERE / "pair.py"), json.dumps(plan)], timeout=timeout, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def one_line(stderr: str) -> str:
    lines = [ln for ln in stderr.splitlines() if ln.startswith("ptint: error:")]
    assert len(lines) == 1 and "Traceback" not in stderr, stderr
    return lines[0]


@pytest.mark.both_ends
def test_lockstep_same_verdict_as_one_process(tmp_path, run):
    """Acceptance: lockstep across two processes (the drive started second) = ptint run with
    the control period and plant step at 1 ms: same verdict, e(tf) within 1e-9 m (measured:
    within 1e-10 m)."""
    out = run_plan(
        [
            {
                "name": "hw",
                "argv": ptint("hardware", CURVE, *PATIENT, "--lockstep", "--quiet",
                              "--out", str(tmp_path / "hw")),
            },
            {"name": "drive", "delay": 1.0,
             "argv": ptint("drive", CURVE, *PATIENT, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["hw"]["rc"] == 0 and out["drive"]["rc"] == 0, out
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    reference = run(CURVE, "{controller: {control_period: 0.001}, multibody: {time_step: 0.001}}").metrics
    assert metrics["status"] == reference["status"] == "ok"
    for seg, ref in zip(metrics["segments"], reference["segments"]):
        assert abs(seg["e_tf_norm"] - ref["e_tf_norm"]) <= 1e-9  # measured: within 1e-10 m
    link = metrics["hardware"]
    assert link["ticks"] == 3000 and link["fault"] is None
    assert link["round_trip_ms"]["count"] >= 2999 and link["round_trip_ms"]["median"] < 50.0
    drive = json.loads((tmp_path / "dr" / "drive.json").read_text())
    assert drive["commands_sent"] >= 3000 and drive["fault"] is None


# what a cell's devices send and take: the arm's and the gripper's drivers, the part tracker
PICK_WIRE = {"IIWA_STATUS", "IIWA_COMMAND", "SCHUNK_WSG_STATUS", "SCHUNK_WSG_COMMAND", "TRACKED_POSES"}
TRUTH_WORDS = r"PART|MOTION|TRUTH|TRUE|GROUND"  # a channel named for part motion or truth


@pytest.mark.slow
def test_pick_lockstep_places_like_one_process(tmp_path, run):
    """Acceptance, the pick world: lockstep across two processes (arm, gripper and the part
    tracker's reports over LCM; the targets, gripper sequence and grasp observer in the drive) =
    ptint run of conveyor_pick_place (its control period and plant step are 1 ms already): every
    part placed, the same verdict, the place error within 1e-12 m (measured: bit-identical, as is
    every arm and part sample of the run; assembly_pick_place's last place 1.3e-15 m apart).  A
    bystander on the group sees every channel on the wire: the devices' own, none named for
    part motion or truth; the drive subscribes to the three its controller side reads."""
    out = run_plan(
        [
            {"name": "wire", "argv": [sys.executable, str(HERE / "listen.py"), "110"], "timeout": 115.0},
            {"name": "hw", "delay": 0.5, "argv": ptint("hardware", PICK, *PATIENT, "--lockstep", "--quiet",
                                                       "--out", str(tmp_path / "hw"))},
            {"name": "drive", "delay": 0.5,
             "argv": ptint("drive", PICK, *PATIENT, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    wire = json.loads(out["wire"]["stdout"])
    wire.pop("LCM_SELF_TEST", None)  # LCM's own, each process's start-up check of the group
    assert set(wire) == PICK_WIRE and not any(re.search(TRUTH_WORDS, c) for c in wire), wire
    assert out["hw"]["rc"] == 0 and out["drive"]["rc"] == 0, out
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    reference = run(PICK).metrics
    assert metrics["status"] == reference["status"] == "ok" and metrics["reasons"] == reference["reasons"]
    assert len(metrics["picks"]) == len(reference["picks"])
    for pick, ref in zip(metrics["picks"], reference["picks"]):
        assert pick["placed"] and ref["placed"]
        assert abs(pick["place_error_mm"] - ref["place_error_mm"]) <= 1e-9  # 1e-12 m (measured 0)
        assert [a["state"] for a in pick["attempt_details"]] == [a["state"] for a in ref["attempt_details"]]
    link = metrics["hardware"]
    assert link["ticks"] == 5000 and link["fault"] is None
    assert link["gripper_commands_taken"] == link["ticks"]  # one gripper command a tick
    assert link["tracker_channel"] == "TRACKED_POSES"
    drive = json.loads((tmp_path / "dr" / "drive.json").read_text())
    assert drive["fault"] is None and drive["commands_sent"] >= 5000
    assert drive["subscribed_channels"] == ["IIWA_STATUS", "SCHUNK_WSG_STATUS", "TRACKED_POSES"]


@pytest.mark.slow
def test_camera_pick_lockstep_places_like_one_process(tmp_path, run):
    """Issue 43, the camera over LCM: conveyor_pick_place_rgbd across two processes in lockstep.
    The hardware sends the station's depth frames (Drake's ``lcmt_image_array``, lossless 32F, on
    ``DRAKE_RGBD_CAMERA_IMAGES_camera``) and no part's motion; the drive runs the perception (its
    fits in a process of its own), the estimators and the plan: the part placed as ``ptint run``
    places it, within 1e-6 m (measured: 1.189753 against 1.189694 mm, 6.1e-8 m: the first
    estimate reaches the drive's command one tick before ``ptint run``'s hold, whose sample at
    0.033 s is simultaneous with the filters' update), and no channel of truth on the wire."""
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", RGBD_PICK, *PATIENT, "--lockstep", "--quiet",
                                         "--out", str(tmp_path / "hw")), "timeout": 400.0},
            {"name": "drive", "argv": ptint("drive", RGBD_PICK, *PATIENT, *LOCKSTEP_DRIVE, "--out",
                                            str(tmp_path / "dr")), "timeout": 400.0},
        ],
        tmp_path,
        timeout=450.0,
    )
    assert out["hw"]["rc"] == 0 and out["drive"]["rc"] == 0, out
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    reference = run(RGBD_PICK).metrics
    assert metrics["status"] == reference["status"] == "ok"
    for pick, ref in zip(metrics["picks"], reference["picks"], strict=True):
        assert pick["placed"] and abs(pick["place_error_mm"] - ref["place_error_mm"]) <= 1e-3, (pick, ref)
        assert pick["t_grasp"] == ref["t_grasp"]
    link = metrics["hardware"]
    assert link["tracker_channel"] is None and link["image_channel"] == "DRAKE_RGBD_CAMERA_IMAGES_camera"
    assert link["frames_sent"] >= 150 and link["fault"] is None  # 30 Hz over 5 s
    drive = json.loads((tmp_path / "dr" / "drive.json").read_text())
    assert drive["subscribed_channels"] == ["IIWA_STATUS", "SCHUNK_WSG_STATUS",
                                            "DRAKE_RGBD_CAMERA_IMAGES_camera"]
    # the fits made in the drive's perception process, one a frame (frame_process)
    assert drive["perception"]["process"] == "own" and drive["perception"]["fit_ms"]["count"] >= 150


@pytest.mark.slow
def test_pick_replan_is_refused_in_one_line(tmp_path):
    """A grasp that is not confirmed would plan anew (a retry or an abort: a new diagram on both
    sides), which is not supported across processes: with a width tolerance of 0.2 mm the pads,
    sunk into the part, read ``empty`` at a read after the close command (measured: t = 1.74 s);
    the hardware then holds the arm and ends with one line; the drive, no longer answered, stops
    with one line."""
    strict = ("--set", "pick.width_tolerance=0.0002")
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", PICK, *PATIENT, *strict, "--lockstep", "--quiet",
                                         "--out", str(tmp_path / "hw"))},
            {"name": "drive", "argv": ptint("drive", PICK, *PATIENT, *strict, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["hw"]["rc"] == 1 and out["drive"]["rc"] == 1
    assert "replanning is not supported across processes" in one_line(out["hw"]["stderr"])
    one_line(out["drive"]["stderr"])
    link = json.loads((tmp_path / "hw" / "metrics.json").read_text())["hardware"]
    assert link["fault_kind"] == "replan unsupported" and 1.58 < link["fault_time"] < 1.86
    assert link["hold"]["speed_at_end"] < 0.05


@pytest.mark.slow
def test_drive_killed_holds_the_arm(tmp_path):
    """The drive SIGKILLed mid-run (real time, at 30 % of the run): the hardware holds the arm
    after exactly its silent periods without a command (here 100: a loaded CI machine stalls a
    process for several ms, ``SLACK``; the default 5 is scripts/link_faults.py's row), joint
    speeds below 0.05 rad/s within 0.2 s, and exits 1 with the reason."""
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", CURVE, *PATIENT, *SLACK, "--out", str(tmp_path / "hw"))},
            {"name": "drive", "argv": ptint("drive", CURVE, *PATIENT), "kill_when": ["hw", " 30 %"]},
        ],
        tmp_path,
    )
    assert out["drive"]["killed"] is not None and out["hw"]["rc"] == 1
    assert "command timeout at t" in one_line(out["hw"]["stderr"])
    link = json.loads((tmp_path / "hw" / "metrics.json").read_text())["hardware"]
    assert link["fault_kind"] == "command timeout" and 0.8 < link["fault_time"] < 2.5
    assert "no command for 100 statuses in a row" in link["fault"] and link["silent_run_max"] == 100
    # from the tick the last command came in to the hold: 100 statuses (the last command's own tick
    # is not silent), one a period, and any tick the hardware skipped after a stall of its own
    silent = (link["fault_time"] - link["last_heard_t"]) / PERIOD
    assert 100 - 1e-6 < silent < 100 + link["ticks_skipped"] + 1e-6, link
    assert link["hold"]["settled_s_after_fault"] <= 0.2 and link["hold"]["speed_at_end"] < 0.05


@pytest.mark.slow
@pytest.mark.parametrize("sig, code", [("SIGTERM", 143), ("SIGINT", 130)])
def test_hardware_signal_holds_and_writes(tmp_path, sig, code):
    """SIGTERM / SIGINT to ``ptint hardware`` mid-run (real time): the arm held for the hold
    time, metrics.json written with the fault ``stopped``, the exit code the shell gives that
    signal; the drive, no longer answered, stops with one line."""
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", CURVE, *PATIENT, *SLACK, "--out", str(tmp_path / "hw")),
             "kill_when": ["hw", " 30 %"], "signal": sig},
            {"name": "drive", "argv": ptint("drive", CURVE, *PATIENT, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["hw"]["rc"] == code and out["drive"]["rc"] == 1, out
    assert f"stopped by {sig} at t" in one_line(out["hw"]["stderr"])
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    link = metrics["hardware"]
    assert metrics["status"] == "failed" and link["fault_kind"] == "stopped" and link["stop_signal"] == sig
    assert 0.8 < link["fault_time"] < 2.5 and link["hold"]["speed_at_end"] < 0.05
    assert link["hold"]["held_until"] >= link["fault_time"] + 0.5 - 2 * PERIOD


@pytest.mark.slow
def test_hardware_killed_stops_the_drive(tmp_path):
    """The hardware SIGKILLed mid-run: the drive exits 1 with one line within its status timeout."""
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", CURVE, *PATIENT, *SLACK), "kill_when": ["hw", " 30 %"]},
            {"name": "drive", "argv": ptint("drive", CURVE, *PATIENT, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["hw"]["killed"] is not None and out["drive"]["rc"] == 1
    assert "no status from the hardware for 0.5 s" in one_line(out["drive"]["stderr"])
    reaction = out["drive"]["ended"] - out["hw"]["killed"]
    assert reaction < 1.5, reaction  # the 0.5 s timeout, writing drive.json, the interpreter's exit
    assert json.loads((tmp_path / "dr" / "drive.json").read_text())["fault"]


@pytest.mark.slow
@pytest.mark.parametrize("mode, words", [("nan", "non-finite torque")])
def test_bad_commands_rejected_and_held(tmp_path, mode, words):
    """A NaN torque: rejected, reported, the arm held (over-limit torques and a wrong size:
    the same path, tests/unit/test_lcm_checks.py with memq://; bad_drive.py has them too)."""
    out = run_plan(
        [
            {
                "name": "hw",
                "argv": ptint("hardware", CURVE, *PATIENT, "--lockstep", "--quiet",
                              "--out", str(tmp_path / "hw")),
            },
            {
                "name": "bad",
                "argv": [sys.executable, str(HERE / "bad_drive.py"), mode, "0.2", "3"],
                "timeout": 40.0,
            },
        ],
        tmp_path,
    )
    assert out["hw"]["rc"] == 1
    assert words in one_line(out["hw"]["stderr"])
    link = json.loads((tmp_path / "hw" / "metrics.json").read_text())["hardware"]
    assert link["fault_kind"] == "bad command" and abs(link["fault_time"] - 0.2) < 1.5 * PERIOD
    assert link["hold"]["speed_at_end"] < 0.05


@pytest.mark.slow
def test_second_sender_detected(tmp_path):
    """A second process answering the statuses too from t = 0.3 s: detected within 10 periods
    (the issue's bound), reported, the arm held."""
    out = run_plan(
        [
            {
                "name": "hw",
                "argv": ptint("hardware", CURVE, *PATIENT, "--lockstep", "--quiet",
                              "--out", str(tmp_path / "hw")),
            },
            {"name": "drive", "argv": ptint("drive", CURVE, *PATIENT)},
            {
                "name": "rogue",
                "argv": [sys.executable, str(HERE / "bad_drive.py"), "rogue", "0.3", "3"],
                "timeout": 40.0,
            },
        ],
        tmp_path,
    )
    # the hardware reads every packet's source address on the command channels (``link.SenderWatch``:
    # a socket of its own beside LCM's, whose subscription queue holds one message and may drop
    # the rogue's): the rogue's first command comes from another address than the drive's
    assert out["hw"]["rc"] == 1 and out["drive"]["rc"] == 1
    hw_line = one_line(out["hw"]["stderr"])
    assert "second sender" in hw_line, hw_line
    link = json.loads((tmp_path / "hw" / "metrics.json").read_text())["hardware"]
    first = int(out["rogue"]["stdout"].split()[1]) * 1e-6  # the stamp of the rogue's first command
    assert link["fault_kind"] == "second sender" and link["sender_check"] == "source address"
    # named within 50 ticks of it: lockstep ticks pass faster than real time, and on a loaded 2-core
    # machine the rogue's packet reached the watch 12 ticks after its stamp (CI, 2026-12-06)
    assert first - 1e-9 <= link["fault_time"] <= first + 50 * PERIOD, (first, link["fault_time"])
    assert link["hold"]["speed_at_end"] < 0.05


@pytest.mark.slow
def test_dropped_status_completes(tmp_path):
    """20 % of the status messages not sent: the lockstep run completes, the loss is reported."""
    out = run_plan(
        [
            {
                "name": "hw",
                "argv": ptint(
                    "hardware",
                    CURVE,
                    "--lockstep",
                    "--quiet",
                    "--drop-status",
                    "0.2",
                    "--set",
                    "duration=1.0",
                    "--set",
                    "interceptions[0].tf=0.8",
                    "--out",
                    str(tmp_path / "hw"),
                ),
            },
            {
                "name": "drive",
                "argv": ptint("drive", CURVE, *PATIENT, "--set", "duration=1.0",
                              "--set", "interceptions[0].tf=0.8"),
            },
        ],
        tmp_path,
    )
    assert out["hw"]["rc"] == 0 and out["drive"]["rc"] == 0, out
    link = json.loads((tmp_path / "hw" / "metrics.json").read_text())["hardware"]
    assert link["ticks"] == 1000
    total = link["statuses_dropped"] + link["statuses_sent"]
    assert (
        0.15 < link["statuses_dropped"] / total < 0.25
        and link["status_resends"] >= link["statuses_dropped"] - 1
    )


@pytest.mark.slow
def test_realtime_lost_gripper_status_does_not_end_the_run(tmp_path):
    """Issue 43: in real time nothing re-sends a companion; one lost gripper status (the hardware's
    test option --drop-companion: the tick at 1 s) costs that tick, not the run — the drive sees
    the next tick's companions first, skips the tick (a late tick for the hardware, which keeps
    the previous torque) and answers the next; the run goes on to its end.  (The silent-peer
    timeouts are set out of the way, 5 s on both sides, and the pace at a quarter of real time: at
    load 7 on this 2-core machine a process stalled for 0.9 s, the arm drifted on the old torque
    and missed its grasp; the hold is not what this test checks.)"""
    out = run_plan(
        [
            {"name": "hw", "argv": ptint("hardware", PICK, *PATIENT, "--silent-periods", "5000", "--quiet",
                                         "--realtime-rate", "0.25", "--drop-companion", "1.0",
                                         "--out", str(tmp_path / "hw"))},
            {"name": "drive", "argv": ptint("drive", PICK, *PATIENT, "--status-timeout", "5",
                                            "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["drive"]["rc"] == 0, out
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    link = metrics["hardware"]
    assert link["companions_dropped"] == 1 and link["fault"] is None, link
    assert link["ticks"] + link["ticks_skipped"] == 5000, link  # (skipped: the hardware's own stalls)
    assert link["ticks_late"] >= 1  # the tick whose gripper status was lost went unanswered
    drive = json.loads((tmp_path / "dr" / "drive.json").read_text())
    # the drive answered to the end: its last status is the last tick's, less the ticks the hardware
    # skipped after its own stalls (a skipped tick publishes no status; CI at load 3: 4.996 s)
    last = 4.998 - 1e-3 * link["ticks_skipped"]
    assert drive["fault"] is None and drive["companions_lost"] == 1 and drive["last_t"] >= last - 1e-9, \
        (drive, link)
    # placed, unless the machine's load made enough late ticks to cost the accuracy (then exit 1)
    assert out["hw"]["rc"] == 0 or (out["hw"]["rc"] == 1 and link["ticks_late"] > 1), out


@pytest.mark.both_ends
def test_in_memory_pair_matches_two_processes(tmp_path):
    """The fallback where no private namespace can be made: hardware and drive as two threads
    over one ``memq://`` LCM (``hardware.in_memory``), the same messages and checks; lockstep
    gives the one-process result (no network at all, so this runs everywhere)."""
    from ptint_drake.hardware.in_memory import run_pair  # noqa: PLC0415
    from ptint_drake.hardware.session import LinkSettings  # noqa: PLC0415
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415

    short = ["duration=1.0", "interceptions[0].tf=0.8", "controller.control_period=0.001",
             "multibody.time_step=0.001"]
    scenario = parse_with_overrides(scenario_text(CURVE)[1], short, CURVE)
    metrics, drive = run_pair(scenario, LinkSettings(period=PERIOD, duration=1.0), tmp_path / "hw")
    reference = run_cached(CURVE, tuple(short))
    assert metrics["status"] == reference.metrics["status"]
    assert abs(metrics["segments"][0]["e_tf_norm"] - reference.metrics["segments"][0]["e_tf_norm"]) < 1e-9
    link = metrics["hardware"]
    assert link["url"].startswith("memq") and link["ticks"] == 1000 and link["fault"] is None
    assert link["round_trip_ms"]["count"] >= 999 and drive["commands_sent"] >= 1000


def test_drive_without_hardware(tmp_path):
    """``ptint drive`` with nobody publishing status: one line after its start-up timeout, exit 1."""
    out = run_plan(
        [
            {
                "name": "drive",
                "argv": ptint("drive", CURVE, "--startup-timeout", "1", "--out", str(tmp_path / "dr")),
            }
        ],
        tmp_path,
    )
    assert out["drive"]["rc"] == 1
    assert "within the start-up timeout of 1 s" in one_line(out["drive"]["stderr"])


@pytest.mark.slow
def test_realtime_run_completes(tmp_path):
    """Real time: the run completes with its latency, lateness and late ticks reported."""
    out = run_plan(
        [
            {"name": "hw",
             "argv": ptint("hardware", CURVE, *PATIENT, *SLACK, "--quiet", "--out", str(tmp_path / "hw"))},
            {"name": "drive", "argv": ptint("drive", CURVE, *PATIENT, "--out", str(tmp_path / "dr"))},
        ],
        tmp_path,
    )
    assert out["drive"]["rc"] == 0, out
    metrics = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    link = metrics["hardware"]
    assert link["mode"] == "realtime" and link["fault"] is None, link
    # every tick published its status, but those the hardware skipped after a stall of its own
    assert link["ticks"] + link["ticks_skipped"] == 3000, link
    # the run completes; its verdict is ok unless the machine was loaded enough that late commands
    # or skipped ticks (each keeps the previous torque) cost the accuracy: then exit 1 with them
    # counted (measured once in CI beside a Monte Carlo: 759 of 3000 ticks late, "segment 0: late", exit 1)
    if out["hw"]["rc"] != 0:
        kept = link["ticks_late"] + link["ticks_skipped"]
        assert out["hw"]["rc"] == 1 and metrics["status"] != "ok" and kept > 0, out
    # paced at the 1 ms period (a free-running lockstep takes a fraction of it); the band is wide
    # because a loaded machine falls behind and catches up (measured 0.88 ms with CI beside it)
    assert link["lateness_ms"] is not None and 0.5 < link["achieved_period_ms"]["median"] < 2.0
    assert np.isfinite(link["round_trip_ms"]["p99"])
    # both loops ran under SCHED_FIFO where the machine permits it (root: CI), else said why
    drive = json.loads((tmp_path / "dr" / "drive.json").read_text())
    if os.geteuid() == 0:  # (LCM's receive threads too: every message passes through them)
        assert link["scheduler"] == drive["scheduler"] == "SCHED_FIFO 10", (link, drive)
        assert link["receive_thread_scheduler"] == drive["receive_thread_scheduler"] == ["SCHED_FIFO 10"]
    else:
        assert "real-time scheduling (SCHED_FIFO 10) refused" in out["drive"]["stderr"]
