"""Speed and accuracy of the bundled scenarios, as JSON (``ptint bench``, ``scripts/benchmark.py``).

For every scenario and configuration it reports the realtime factor (simulated s
/ wall s of the simulation), integrator steps, derivative evaluations, µs per
derivative evaluation, and e(tf) of every segment next to a tight-tolerance
reference run (runge_kutta5, accuracy 1e-10, max step 10 ms) — speed that loses
accuracy does not count.  Configurations: the default (fused, tanh), the five
wired blocks (``blocks``), and the paper's ``sign`` law.
"""

from __future__ import annotations

import json
import platform
import time

from ptint_drake.scenario import bundled_scenarios, parse_with_overrides, scenario_text
from ptint_drake.simulation import simulate

CONFIGS = {
    "default": "",
    "blocks": "controller: {implementation: blocks}",
    "sign": "controller: {switching: sign}",
}
REFERENCE = ("simulator: {integration_scheme: runge_kutta5, accuracy: 1.0e-10, "
             "max_step_size: 0.01}")


def _run(name: str, overrides: str) -> dict:
    _, text = scenario_text(name)
    scenario = parse_with_overrides(text, overrides, name) if overrides else parse_with_overrides(
        text, "{}", name)
    return simulate(scenario, check=False).metrics


def benchmark(names=None, configs=("default", "blocks", "sign"), reference: bool = True,
              progress=None) -> dict:
    names = list(names or bundled_scenarios())
    out = {"machine": {"python": platform.python_version(), "processor": platform.machine(),
                       "cpus": __import__("os").cpu_count()},
           "reference": REFERENCE if reference else None, "scenarios": {}}
    t_start = time.perf_counter()
    for name in names:
        entry = {}
        ref = _run(name, REFERENCE) if reference else None
        if ref is not None:
            entry["reference_e_tf"] = [s["e_tf_norm"] for s in ref["segments"]]
            entry["reference_steps"] = ref["sim"]["steps"]
        for config in configs:
            if progress:
                progress(f"{name} {config}")
            m = _run(name, CONFIGS[config])
            sim = m["sim"]
            row = {
                "realtime_factor": round(sim["realtime_factor"], 3),
                "wall_time_s": round(sim["wall_time_s"], 4),
                "steps": sim["steps"],
                "derivative_evaluations": sim["derivative_evaluations"],
                "us_per_derivative": round(1e6 * sim["wall_time_s"] / sim["derivative_evaluations"], 2),
                "e_tf": [s["e_tf_norm"] for s in m["segments"]],
            }
            if ref is not None:
                row["e_tf_error_vs_reference"] = [
                    abs(a - b) for a, b in zip(row["e_tf"], entry["reference_e_tf"])]
            entry[config] = row
        if "default" in entry and "blocks" in entry:
            entry["speedup_default_vs_blocks"] = round(
                entry["default"]["realtime_factor"] / entry["blocks"]["realtime_factor"], 2)
        out["scenarios"][name] = entry
    out["total_wall_s"] = round(time.perf_counter() - t_start, 1)
    return out


def sweep_benchmark(name: str = "curve_b075_tf15", betas=(0.25, 0.5, 0.75),
                    tfs=(1.2, 1.5, 1.9), workers=(1, 2)) -> dict:
    """Wall time of a 3 × 3 ``ptint sweep`` grid with 1 and 2 worker processes."""
    from ptint_drake.studies.sweep import timed_sweep

    _, text = scenario_text(name)
    walls = {w: timed_sweep(text, name, betas, tfs, w) for w in workers}
    return {"scenario": name, "grid": [list(betas), list(tfs)],
            "wall_s": {str(w): round(s, 3) for w, s in walls.items()},
            "speedup_2_vs_1": round(walls[1] / walls[2], 2) if 1 in walls and 2 in walls else None}


def main(argv=None) -> int:
    import argparse

    parser = argparse.ArgumentParser(prog="ptint bench", description=__doc__.split("\n")[0])
    parser.add_argument("scenarios", nargs="*", help="default: every bundled scenario")
    parser.add_argument("--configs", default="default,blocks,sign",
                        help="comma-separated subset of " + ",".join(CONFIGS))
    parser.add_argument("--no-reference", action="store_true", help="skip the tight reference runs")
    parser.add_argument("--sweep", action="store_true",
                        help="also time a 3 x 3 sweep with 1 and 2 worker processes")
    args = parser.parse_args(argv)
    configs = [c for c in args.configs.split(",") if c]
    unknown = [c for c in configs if c not in CONFIGS]
    if unknown:
        parser.error(f"--configs: unknown {', '.join(unknown)}")
    result = benchmark(args.scenarios or None, configs, not args.no_reference,
                       progress=lambda s: print(f"bench: {s}", file=__import__("sys").stderr))
    if args.sweep:
        result["sweep"] = sweep_benchmark()
    print(json.dumps(result, indent=2))
    return 0
