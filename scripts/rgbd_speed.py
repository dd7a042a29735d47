"""A camera pick run's speed (issue 34: at least 0.5x real time end to end), as JSON.

    python scripts/rgbd_speed.py [SCENARIO]      (default assembly_pick_place_rgbd)

One run in this process (no figures, no replay): metrics.json's ``realtime_factor`` (simulated
time over the wall time of simulation, series and metrics) and ``simulation_realtime_factor``,
and this process's CPU seconds over the run (user, system; ``resource.getrusage``) with the
simulated time per CPU second — on a shared machine the wall time counts the other processes'
load, the CPU time much less so.  Run it from two checkouts in turn (A B A B) to compare them.
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import time


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default="assembly_pick_place_rgbd")
    args = parser.parse_args()
    from ptint_drake.config.yaml_io import drake_version  # noqa: PLC0415
    from ptint_drake.simulation import simulate  # noqa: PLC0415
    from ptint_drake.simulation.scenario import load_scenario  # noqa: PLC0415

    scenario = load_scenario(args.scenario)
    before, start = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    result = simulate(scenario)
    after, wall = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter() - start
    sim, m = result.metrics["sim"], result.metrics
    user, system = after.ru_utime - before.ru_utime, after.ru_stime - before.ru_stime
    print(json.dumps({
        "scenario": args.scenario, "drake": drake_version(), "python": platform.python_version(),
        "status": m["status"], "simulated_s": sim["simulated_s"],
        "realtime_factor": round(sim["realtime_factor"], 3),
        "simulation_realtime_factor": round(sim["simulation_realtime_factor"], 3),
        "wall_s": round(wall, 2), "user_cpu_s": round(user, 2), "sys_cpu_s": round(system, 2),
        "simulated_per_cpu_s": round(sim["simulated_s"] / (user + system), 3),
        "placed": [p.get("placed") for p in m.get("picks", [])],
        "place_error_mm": [None if p.get("place_error_mm") is None else round(p["place_error_mm"], 3)
                           for p in m.get("picks", [])],
    }))


if __name__ == "__main__":
    main()
