"""Where a pick-and-place run's time goes (issue 20), as JSON.

    .venv/bin/python scripts/pick_speed.py [SCENARIO] [--profile]

Without ``--profile``: the run's wall time and its realtime factor (metrics.json's ``sim``), best of
one run.  With ``--profile``: one more run under cProfile, its time split by who spends it —
Drake's C++ (the discrete plant with its contact solver, the integrator, the loggers: the time
inside ``AdvanceTo`` not spent in a Python system), the controller (the interceptor's Python
systems), the pick systems (targets, part poses, gripper driver, contact probe) and the
post-processing (series, metrics).  cProfile slows Python down, so the shares overstate Python
somewhat; the plain run gives the realtime factor.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import time

GROUPS = {
    "controller": ("ptint_drake/systems/", "ptint_drake/controllers/"),
    "pick systems": ("ptint_drake/pick/targets.py", "ptint_drake/pick/part_pose.py",
                     "ptint_drake/pick/probe.py", "ptint_drake/systems/hand/gripper.py"),
    "post-processing": ("ptint_drake/pick/metrics.py", "ptint_drake/pick/run.py:pick_series",
                        "ptint_drake/verdict/metrics.py"),
}


def _group(filename: str, function: str) -> str | None:
    key = f"{filename}:{function}"
    for name in ("pick systems", "post-processing", "controller"):
        if any(p in key for p in GROUPS[name]):
            return name
    return None


def split(stats: pstats.Stats) -> dict:
    """Seconds per group (self time), and the C++ share (simulate_pick's own time)."""
    out = {name: 0.0 for name in GROUPS}
    cxx = 0.0
    for (filename, _, function), (_, _, tottime, _, _) in stats.stats.items():
        if filename.endswith("pick/run.py") and function == "simulate_pick":
            cxx += tottime
            continue
        group = _group(filename, function)
        if group is not None:
            out[group] += tottime
    return {"drake_cxx (plant, contact solver, integrator, loggers)": cxx} | out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default="assembly_pick_place")
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()
    from ptint_drake.simulation import simulate  # noqa: PLC0415
    from ptint_drake.simulation.scenario import load_scenario  # noqa: PLC0415

    scenario = load_scenario(args.scenario)
    t0 = time.perf_counter()
    result = simulate(scenario)
    report = {"scenario": args.scenario, "simulated_s": scenario.duration,
              "wall_s": time.perf_counter() - t0, "realtime_factor": result.metrics["sim"]["realtime_factor"],
              "status": result.metrics["status"]}
    if args.profile:
        profiler = cProfile.Profile()
        profiler.enable()
        simulate(scenario)
        profiler.disable()
        stats = pstats.Stats(profiler)
        report["profiled_total_s"] = stats.total_tt
        report["profiled_split_s"] = split(stats)
    print(json.dumps(report, indent=2))


if __name__ == "__main__":
    main()
