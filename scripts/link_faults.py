"""The hardware path's fault table, measured: ``ptint hardware`` + ``ptint drive`` as two real
processes in a private network namespace (``tests/lcm_link``), one row per fault, printed as JSON.

    python scripts/link_faults.py [--runs N] [--scenario NAME] [--out DIR]

Rows: ``realtime`` N clean real-time runs (a hold there is spurious); ``drive SIGKILL`` (the
drive killed at 30 % of the run: periods from its last command to the hold); ``hardware SIGTERM``
and ``hardware SIGINT`` (held, metrics.json written, the exit code); ``second drive`` (a second
``ptint drive`` started mid-run: named as the second sender); ``lost gripper status`` (the pick
scenario, ``--pick-scenario``, with the gripper status of the tick at 1 s not sent, once: in real
time at a quarter of real time — the camera-free pick's station keeps that pace on a loaded
2-core machine — and in lockstep: the drive skips the tick, or the status's re-send brings it).
Each row gives the reaction in control periods, whether the arm was held (joint speeds below
0.05 rad/s at the end), the files written, and the drive's exit code, fault and lost companions.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from lcm_link.netns import namespace_problem, run_in_netns  # noqa: E402

import numpy as np  # noqa: E402

from ptint_drake.hardware.link_record import LinkSettings  # noqa: E402

BUDGET = LinkSettings.budget  # the part of T a real-time tick waits for its command

PAIR = ROOT / "tests" / "lcm_link" / "pair.py"
PATIENT = ("--startup-timeout", "60")


def ptint(*args: str) -> list[str]:
    return [sys.executable, "-m", "ptint_drake.cli", *args]


def run_plan(plan: list[dict], cwd: Path, timeout: float = 300.0) -> dict:
    done = run_in_netns([sys.executable, str(PAIR), json.dumps(plan)], timeout=timeout, cwd=cwd)
    if done.returncode != 0:
        raise SystemExit(f"link_faults: the plan failed: {done.stderr[-500:]}")
    return json.loads(done.stdout)


def row(name: str, out: dict, folder: Path, proc: str = "hw") -> dict:
    """What one fault run shows: exit codes, the hardware's link block, the files written."""
    metrics = folder / "hw" / "metrics.json"
    link = json.loads(metrics.read_text())["hardware"] if metrics.is_file() else {}
    period = link.get("period") or 1e-3
    reaction = None
    heard = link.get("last_heard_t", link.get("last_command_t"))
    if link.get("fault_time") is not None and heard is not None:
        reaction = round((link["fault_time"] - heard) / period, 1)
    hold = link.get("hold") or {}
    return {
        "fault": name,
        "exit": {k: v["rc"] for k, v in out.items()},
        "fault_kind": link.get("fault_kind"),
        "message": link.get("fault"),
        "reaction_periods": reaction,  # simulated periods from the tick the last command came in
        "silent_statuses": link.get("silent_run_max"),
        "signal_to_hold_ms": _signal_to_hold(out, folder, proc),
        "ticks_skipped": link.get("ticks_skipped"),
        "held": hold.get("speed_at_end") is not None and hold["speed_at_end"] < 0.05,
        "settled_s_after_fault": hold.get("settled_s_after_fault"),
        "ticks_late": link.get("ticks_late"),
        "late_run_max": link.get("late_run_max"),
        "files": sorted(p.name for p in (folder / "hw").glob("*")) if (folder / "hw").is_dir() else [],
        "ticks": link.get("ticks"),
        "drive": _drive(folder),
        "late_sides": late_sides(folder, BUDGET * period / (link.get("realtime_rate") or 1.0)),
    }


def late_sides(folder: Path, budget_s: float) -> Optional[dict]:
    """On which side each late tick of a real-time run was late, from the hardware's per-tick
    wall times (series.npz ``link_*``) and the drive's (drive_series.npz): ``drive woke late``
    (the status reached the idle drive's loop after the tick's deadline), ``drive busy`` (it was
    still answering older statuses), ``drive computed late`` (received in time, answered after
    the deadline), ``hardware handled late`` (answered in time, handled by the hardware after
    its wait ended), ``not answered`` (the drive never answered that status); with the count of
    the late ticks in runs of 3 or more, and the median delay of each segment (ms)."""
    hw, dr = folder / "hw" / "series.npz", folder / "dr" / "drive_series.npz"
    if not hw.is_file() or not dr.is_file():
        return None
    h, d = np.load(hw), np.load(dr)
    drive = {int(u): (r, x) for u, r, x in zip(d["stamp"], d["recv_wall"], d["sent_wall"])}
    late_at = dict(zip(h["link_late_utime"].tolist(), h["link_late_wall"]))
    late = np.flatnonzero(np.isnan(h["link_tick_answered"]))
    runs = np.split(late, np.flatnonzero(np.diff(late) > 1) + 1) if late.size else []
    sides, delays = {}, {"to_drive_ms": [], "drive_ms": [], "to_hardware_ms": []}
    for k in late:
        u, sent = int(round(h["link_tick_t"][k] * 1e6)), h["link_tick_sent"][k]
        prev = drive.get(int(round(h["link_tick_t"][k - 1] * 1e6))) if k else None
        side = _side(sent, sent + budget_s, drive.get(u), prev)
        sides[side] = sides.get(side, 0) + 1
        if u in drive:
            r, x = drive[u]
            delays["to_drive_ms"].append((r - sent) * 1e3)
            delays["drive_ms"].append((x - r) * 1e3)
            if u in late_at:
                delays["to_hardware_ms"].append((late_at[u] - x) * 1e3)
    return {"ticks_late": int(late.size), "in_runs_of_3_or_more": sum(len(r) for r in runs if len(r) >= 3),
            "sides": sides,
            "median_ms": {k: round(float(np.median(v)), 3) if v else None for k, v in delays.items()}}


def _side(sent: float, deadline: float, answer: Optional[tuple], previous: Optional[tuple]) -> str:
    """The side a late tick was late on (``late_sides``)."""
    if answer is None:
        return "not answered"
    received, answered = answer
    if received > deadline:
        return "drive busy" if previous is not None and previous[1] > sent else "drive woke late"
    return "drive computed late" if answered > deadline else "hardware handled late"


def _signal_to_hold(out: dict, folder: Path, proc: str) -> Optional[float]:
    """Wall ms from the signal sent to a process of the plan (the drive killed) to the end of the
    hardware tick that held the arm (series.npz ``link_tick_waited``: one clock, CLOCK_MONOTONIC)."""
    killed = [v for k, v in out.items() if k != proc and v.get("killed") is not None]
    series = folder / "hw" / "series.npz"
    if not killed or not series.is_file():
        return None
    waited = np.load(series)["link_tick_waited"]
    if not waited.size:
        return None
    return round(1e3 * (float(waited[-1]) - (killed[0]["origin"] + killed[0]["killed"])), 2)


def _drive(folder: Path) -> dict:
    """The drive's own account (drive.json): its fault and the ticks it skipped for a lost companion."""
    path = folder / "dr" / "drive.json"
    if not path.is_file():
        return {}
    drive = json.loads(path.read_text())
    return {"fault": drive.get("fault"), "companions_lost": drive.get("companions_lost"),
            "last_t": drive.get("last_t")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="clean real-time runs (default 10)")
    parser.add_argument("--scenario", default="curve_b075_tf15")
    parser.add_argument("--pick-scenario", default="conveyor_pick_place",
                        help="the lost-companion rows' scenario")
    parser.add_argument("--only", help="comma-separated rows: realtime,kill,sigterm,sigint,second,companion")
    parser.add_argument("--out", help="keep each run's folders (hw/, dr/) here (default: a temporary folder)")
    args = parser.parse_args()
    problem = namespace_problem()
    if problem:
        raise SystemExit(f"link_faults: no private network namespace: {problem}")
    name = args.scenario
    only = (set(args.only.split(",")) if args.only
            else {"realtime", "kill", "sigterm", "sigint", "second", "companion"})
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(args.out) if args.out else Path(tmp)
        base.mkdir(parents=True, exist_ok=True)

        def case(label, plan_of):
            folder = base / f"{label}_{len(rows)}"
            folder.mkdir()
            out = run_plan(plan_of(folder), folder)
            rows.append(row(label, out, folder))
            print(json.dumps(rows[-1]), file=sys.stderr)

        def hw(folder, *extra, scenario=name):
            argv = ptint("hardware", scenario, *PATIENT, *extra, "--out", str(folder / "hw"))
            return {"name": "hw", "argv": argv}

        def drive(label="drive", folder=None, scenario=name, extra=(), **more):
            out = ("--out", str(folder / "dr")) if folder is not None else ()
            return {"name": label, "argv": ptint("drive", scenario, *PATIENT, *extra, *out), **more}

        if "realtime" in only:
            for _ in range(args.runs):
                case("realtime (no fault)", lambda f: [hw(f, "--quiet"), drive(folder=f)])
        if "kill" in only:
            case("drive SIGKILL", lambda f: [hw(f), drive(kill_when=["hw", " 30 %"])])
        for sig in ("SIGTERM", "SIGINT"):
            if sig.lower() in only:
                case(f"hardware {sig}",
                     lambda f, sig=sig: [{**hw(f), "kill_when": ["hw", " 30 %"], "signal": sig}, drive()])
        if "second" in only:
            case("second drive", lambda f: [hw(f), drive(), drive("drive2", delay=1.0)])
        if "companion" in only:
            pick, lost = args.pick_scenario, ("--drop-companion", "1.0", "--quiet")
            slow = ("--realtime-rate", "0.25", "--silent-periods", "5000")  # (the pace: docstring)
            case("lost gripper status (real time)", lambda f: [
                hw(f, *lost, *slow, scenario=pick),
                drive(folder=f, scenario=pick, extra=("--status-timeout", "5"))])
            case("lost gripper status (lockstep)", lambda f: [
                hw(f, *lost, "--lockstep", scenario=pick), drive(folder=f, scenario=pick)])
    clean = [r for r in rows if r["fault"] == "realtime (no fault)"]
    summary = {"rows": rows, "realtime_runs": len(clean),
               "spurious_holds": sum(1 for r in clean if r["fault_kind"] is not None)}
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
