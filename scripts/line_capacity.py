"""The line's capacity, measured against the model's estimate (issue 44), as JSON.

Runs the surplus line (``line_surplus``: arrivals well above capacity, so the arm is never short
of a part) over seeds, each a ``ptint run`` in a child process, and reads per seed metrics.json
``line``: the tasks over their busy span (``tasks_per_minute_busy``: the first approach's start
to the last retreat's end — the arm's saturated throughput), the placed parts, the mean cycle, and
the min-tf model's estimate (``capacity_estimate``, ``line.cycle.estimate``); then the pooled
measured throughput (every seed's tasks over every seed's busy span) and its ratio to the
estimate (issue 44: within ±20 %).

    PYTHONPATH=$PWD python scripts/line_capacity.py [--scenario line_surplus] [--seeds 3] [--first 0]
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path


def run_seed(scenario: str, seed: int) -> dict:
    """One seed's capacity numbers and the child's CPU seconds."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        args = [sys.executable, "-m", "ptint_drake", "run", scenario, "--quiet", "--no-replay",
                "--no-figures", "--out", str(out), "--set", f"pick.line.seed={seed}"]
        done = subprocess.run(args, capture_output=True, text=True, check=False)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        if not (out / "metrics.json").is_file():
            return {"seed": seed, "error": done.stderr.strip()[-300:], "cpu_s": cpu}
        line = json.loads((out / "metrics.json").read_text())["line"]
    return {"seed": seed, "entered": line["entered"], "placed": line["placed"], "tasks": len(line["cycle_s"]),
            "span_s": line["tasks_span_s"], "busy_picks_per_minute": line["tasks_per_minute_busy"],
            "mean_cycle_s": line["mean_cycle_s"], "estimate": line["capacity_estimate"],
            "planning_ms": line["planning_ms"],
            "warning": [w for w in done.stderr.splitlines() if "capacity" in w],
            "cpu_s": round(cpu, 1)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="line_surplus")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--first", type=int, default=0)
    args = parser.parse_args()
    rows = []
    for seed in range(args.first, args.first + args.seeds):
        rows.append(run_seed(args.scenario, seed))
        print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    ok = [r for r in rows if "error" not in r and r["span_s"]]
    tasks, span = sum(r["tasks"] for r in ok), sum(r["span_s"] for r in ok)
    measured = 60.0 * tasks / span if span else None
    estimate = ok[0]["estimate"]["picks_per_minute"] if ok else None
    print(json.dumps({"scenario": args.scenario, "seeds": len(rows), "failed_runs": len(rows) - len(ok),
                      "measured_picks_per_minute": measured, "estimated_picks_per_minute": estimate,
                      "ratio": measured / estimate if measured and estimate else None,
                      "placed": sum(r["placed"] for r in ok), "entered": sum(r["entered"] for r in ok),
                      "runs": rows}, indent=1))


if __name__ == "__main__":
    main()
