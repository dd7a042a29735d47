"""The call time of the minimum phase time model (``worlds.pick.phase_time``, issue 44), as JSON.

``python scripts/bench_phase_time.py [scenario] [--calls N]`` (default ``conveyor_pick_place``,
20 calls of each kind): the model of the scenario's station is built (``build_s``), then
``min_tf`` is called on ways it has not seen (each call's target moved 1 mm on, so the cache of
postures misses): a carry to a fixed point with a payload (``fixed_ms``), an approach to a part
riding its belt (``riding_ms``), and the same calls again (``cached_ms``: the postures cached); the
first call of the process (Drake's and numba's start-up) is reported apart (``first_ms``), and a
whole pick cycle (``cycle_ms``: six phases, ``cycle_time``) with its estimate (``cycle_s``,
``picks_per_minute``).  ``--samples 11``: the coarser option (``phase_time.COARSE``).  Times are
medians (ms) of wall time on this machine.
"""

from __future__ import annotations

import argparse
import json
import platform
import time

import numpy as np

from ptint_drake.config.yaml_io import drake_version
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.verdict.run_warnings import SPEED_SAMPLES
from ptint_drake.worlds.pick.phase_time import COARSE, PhaseTimes, cycle_time
from ptint_drake.worlds.pick.ways import nominal


def _timed(call) -> tuple:
    start = time.perf_counter()
    value = call()
    return value, 1e3 * (time.perf_counter() - start)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario", nargs="?", default="conveyor_pick_place")
    parser.add_argument("--calls", type=int, default=20)
    parser.add_argument("--samples", type=int, default=SPEED_SAMPLES,
                        help=f"samples of each profile ({COARSE}: the coarser option)")
    args = parser.parse_args()
    scenario = load_scenario(args.scenario)
    model, build_ms = _timed(lambda: PhaseTimes.of(scenario))
    model.samples = args.samples
    world = nominal(scenario, model.arm)
    p0, ride = world.parts[0]
    place = world.places[0]
    clear = np.array([0.0, 0.0, scenario.pick.tasks[0].clearance])
    lift = np.array([0.0, 0.0, scenario.pick.tasks[0].lift_height])
    step = np.array([0.0, 0.001, 0.0])
    _, first_ms = _timed(lambda: model.min_tf(p0 + lift, place + lift, None, 0.1))
    fixed = [_timed(lambda k=k: model.min_tf(p0 + lift + k * step, place + lift, None, 0.1))[1]
             for k in range(1, args.calls + 1)]
    riding = [_timed(lambda k=k: model.min_tf(place + clear, p0 + clear + k * step, ride))[1]
              for k in range(1, args.calls + 1)]
    cached = [_timed(lambda k=k: model.min_tf(place + clear, p0 + clear + k * step, ride))[1]
              for k in range(1, args.calls + 1)]
    cycle, cycle_ms = _timed(lambda: cycle_time(model, p0 - 5 * step, ride, place,
                                                mass=scenario.pick.parts[0].mass))
    print(json.dumps({
        "scenario": scenario.name, "calls": args.calls, "samples": args.samples,
        "build_s": round(build_ms / 1e3, 3),
        "first_ms": round(first_ms, 1), "fixed_ms": round(float(np.median(fixed)), 1),
        "riding_ms": round(float(np.median(riding)), 1), "cached_ms": round(float(np.median(cached)), 1),
        "cycle_ms": round(cycle_ms, 1), "cycle_s": round(cycle.total, 3),
        "picks_per_minute": round(cycle.capacity, 2),
        "phases_s": {k: round(v, 3) for k, v in cycle.phases.items()},
        "python": platform.python_version(), "drake": drake_version()}, indent=1))


if __name__ == "__main__":
    main()
