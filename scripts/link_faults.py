"""The hardware path's fault table, measured: ``ptint hardware`` + ``ptint drive`` as two real
processes in a private network namespace (``tests/lcm_link``), one row per fault, printed as JSON.

    python scripts/link_faults.py [--runs N] [--scenario NAME] [--out DIR]

Rows: ``realtime`` N clean real-time runs (a hold there is spurious); ``drive SIGKILL`` (the
drive killed at 30 % of the run: periods from its last command to the hold); ``hardware SIGTERM``
and ``hardware SIGINT`` (held, metrics.json written, the exit code); ``second drive`` (a second
``ptint drive`` started mid-run: named as the second sender).  Each row gives the reaction in
control periods, whether the arm was held (joint speeds below 0.05 rad/s at the end) and the
files written.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from lcm_link.netns import namespace_problem, run_in_netns  # noqa: E402

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
    if link.get("fault_time") is not None and link.get("last_command_t") is not None:
        reaction = round((link["fault_time"] - link["last_command_t"]) / period, 1)
    hold = link.get("hold") or {}
    return {
        "fault": name,
        "exit": {k: v["rc"] for k, v in out.items()},
        "fault_kind": link.get("fault_kind"),
        "message": link.get("fault"),
        "reaction_periods": reaction,
        "held": hold.get("speed_at_end") is not None and hold["speed_at_end"] < 0.05,
        "settled_s_after_fault": hold.get("settled_s_after_fault"),
        "ticks_late": link.get("ticks_late"),
        "late_run_max": link.get("late_run_max"),
        "files": sorted(p.name for p in (folder / "hw").glob("*")) if (folder / "hw").is_dir() else [],
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="clean real-time runs (default 10)")
    parser.add_argument("--scenario", default="curve_b075_tf15")
    parser.add_argument("--only", help="comma-separated rows: realtime,kill,sigterm,sigint,second")
    args = parser.parse_args()
    problem = namespace_problem()
    if problem:
        raise SystemExit(f"link_faults: no private network namespace: {problem}")
    name = args.scenario
    only = set(args.only.split(",")) if args.only else {"realtime", "kill", "sigterm", "sigint", "second"}
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(tmp)

        def case(label, plan_of):
            folder = base / f"{label}_{len(rows)}"
            folder.mkdir()
            out = run_plan(plan_of(folder), folder)
            rows.append(row(label, out, folder))
            print(json.dumps(rows[-1]), file=sys.stderr)

        def hw(folder, *extra):
            argv = ptint("hardware", name, *PATIENT, *extra, "--out", str(folder / "hw"))
            return {"name": "hw", "argv": argv}

        def drive(label="drive", **more):
            return {"name": label, "argv": ptint("drive", name, *PATIENT), **more}

        if "realtime" in only:
            for _ in range(args.runs):
                case("realtime (no fault)", lambda f: [hw(f, "--quiet"), drive()])
        if "kill" in only:
            case("drive SIGKILL", lambda f: [hw(f), drive(kill_when=["hw", " 30 %"])])
        for sig in ("SIGTERM", "SIGINT"):
            if sig.lower() in only:
                case(f"hardware {sig}",
                     lambda f, sig=sig: [{**hw(f), "kill_when": ["hw", " 30 %"], "signal": sig}, drive()])
        if "second" in only:
            case("second drive", lambda f: [hw(f), drive(), drive("drive2", delay=1.0)])
    clean = [r for r in rows if r["fault"] == "realtime (no fault)"]
    summary = {"rows": rows, "realtime_runs": len(clean),
               "spurious_holds": sum(1 for r in clean if r["fault_kind"] is not None)}
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
