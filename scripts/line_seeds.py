"""Measures a line scenario over seeds (issue 44) and prints JSON: per seed the parts released,
entered and placed, picks per minute, the failures' reasons, with the camera its IDSW and the
parts not seen, the CPU seconds of the run and the realtime factor in CPU (simulated / CPU
seconds); then the pooled numbers (placed / entered over every seed).

Each seed is one ``ptint run SCENARIO --set pick.line.seed=K`` in a child process, one after the
other (the CPU seconds are the child's, from ``resource.getrusage(RUSAGE_CHILDREN)``).

    PYTHONPATH=$PWD python scripts/line_seeds.py [--scenario line_short] [--seeds 10] [--first 0]
                                                 [--set KEY=VALUE ...]
"""

from __future__ import annotations

import argparse
import collections
import json
import resource
import subprocess
import sys
import tempfile
from pathlib import Path


def run_seed(scenario: str, seed: int, overrides: list) -> dict:
    """One seed's run: its ``line`` numbers and the child's CPU seconds."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        args = [sys.executable, "-m", "ptint_drake", "run", scenario, "--quiet", "--no-replay",
                "--no-figures", "--out", str(out), "--set", f"pick.line.seed={seed}"]
        for o in overrides:
            args += ["--set", o]
        done = subprocess.run(args, capture_output=True, text=True, check=False)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        if not (out / "metrics.json").is_file():
            return {"seed": seed, "error": done.stderr.strip()[-300:], "cpu_s": cpu}
        metrics = json.loads((out / "metrics.json").read_text())
    line = metrics["line"]
    reasons = collections.Counter(p["reason"] for p in line["parts"] if p["entered"] and not p["placed"])
    return {"seed": seed, "released": line["released"], "entered": line["entered"], "placed": line["placed"],
            "picks_per_minute": line["picks_per_minute"], "mean_cycle_s": line["mean_cycle_s"],
            "replaced": len(line["replaced"]), "reasons": dict(reasons), "status": metrics["status"],
            "idsw": line.get("idsw"), "not_seen": line.get("not_seen", 0),  # (the camera's line)
            "cpu_s": round(cpu, 1), "realtime_cpu": round(metrics["duration"] / cpu, 3)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenario", default="line_short")
    parser.add_argument("--seeds", type=int, default=10)
    parser.add_argument("--first", type=int, default=0)
    parser.add_argument("--set", action="append", default=[], dest="overrides")
    args = parser.parse_args()
    rows = []
    for seed in range(args.first, args.first + args.seeds):
        rows.append(run_seed(args.scenario, seed, args.overrides))
        print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    ok = [r for r in rows if "error" not in r]
    entered, placed = sum(r["entered"] for r in ok), sum(r["placed"] for r in ok)
    reasons = collections.Counter()
    for r in ok:
        reasons.update(r["reasons"])
    print(json.dumps({"scenario": args.scenario, "overrides": args.overrides, "seeds": len(rows),
                      "failed_runs": len(rows) - len(ok), "entered": entered, "placed": placed,
                      "placed_fraction": placed / entered if entered else None,
                      "picks_per_minute_mean": sum(r["picks_per_minute"] for r in ok) / max(len(ok), 1),
                      "reasons": dict(reasons), "idsw": sum(r.get("idsw") or 0 for r in ok),
                      "cpu_s_per_run": sum(r["cpu_s"] for r in rows) / max(len(rows), 1), "runs": rows},
                     indent=1))


if __name__ == "__main__":
    main()
