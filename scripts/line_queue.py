"""The loss no scheduler avoids on a line whose parts wait a bounded time, as JSON (issue 44).

A single arm serving parts one at a time is a queue with deterministic service: each pick holds
the arm ``D`` s (its grasp-to-grasp cycle), and a part waits at most ``W`` s for the arm to start
on it (its reach window less the lift's slack and the descend) before it leaves unpicked.  Served
in arrival order (earliest deadline first: equal patience), the fraction lost is what any order
loses at that cycle.  The arrivals are the line's own process (``line.arrivals``: Poisson with a
dead time ``min_gap``, or ``jittered``), ``belts`` independent streams of ``rate`` parts/s each,
drawn for ``span`` s per seed; pooled over ``--seeds`` seeds.

    python scripts/line_queue.py [--rate 0.083] [--belts 2] [--process poisson] [--span 48]
                                 [--cycles 3 4] [--waits 4 6 10 14] [--seeds 400]

docs/pick_place.md "The window against the cycle".
"""

from __future__ import annotations

import argparse
import json

import numpy as np


def releases(rng: np.random.Generator, process: str, rate: float, span: float, min_gap: float,
             jitter: float) -> list[float]:
    """One belt's release times over [0, span) (``line.arrivals.release_times``' processes; a
    jittered belt starts at a uniform phase)."""
    mean, out = 1.0 / rate, []
    t = rng.exponential(mean - min_gap) if process == "poisson" else rng.uniform(0.0, mean)
    while t < span:
        out.append(float(t))
        if process == "poisson":
            t += min_gap + rng.exponential(mean - min_gap)
        else:
            t += max(min_gap, mean * (1.0 + rng.uniform(-jitter, jitter)))
    return out


def lost(arrivals: list[float], cycle: float, wait: float) -> int:
    """Parts lost by one arm serving ``arrivals`` in order, ``cycle`` s each, a part leaving after
    ``wait`` s unserved."""
    free, count = 0.0, 0
    for a in sorted(arrivals):
        start = max(free, a)
        if start - a > wait:
            count += 1
            continue
        free = start + cycle
    return count


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rate", type=float, default=0.083, help="parts/s per belt")
    parser.add_argument("--belts", type=int, default=2)
    parser.add_argument("--process", choices=("poisson", "jittered"), default="poisson")
    parser.add_argument("--min-gap", type=float, default=0.6)
    parser.add_argument("--jitter", type=float, default=0.3)
    parser.add_argument("--span", type=float, default=48.0, help="s of releases per seed")
    parser.add_argument("--cycles", type=float, nargs="+", default=[3.0, 4.0])
    parser.add_argument("--waits", type=float, nargs="+", default=[4.0, 6.0, 10.0, 14.0])
    parser.add_argument("--seeds", type=int, default=400)
    args = parser.parse_args()
    draws = []
    for seed in range(args.seeds):
        rng = np.random.default_rng(seed)
        draws.append([t for _ in range(args.belts)
                      for t in releases(rng, args.process, args.rate, args.span, args.min_gap, args.jitter)])
    parts = sum(len(d) for d in draws)
    rows = [{"cycle_s": c, "wait_s": w, "lost": round(sum(lost(d, c, w) for d in draws) / parts, 4)}
            for c in args.cycles for w in args.waits]
    print(json.dumps({"process": args.process, "rate_per_belt": args.rate, "belts": args.belts,
                      "parts": parts, "loss": rows}))


if __name__ == "__main__":
    main()
