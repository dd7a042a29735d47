"""The catch table and figure of docs/catch.md (issue 46) from ``ptint robust`` folders of a catch
scenario: the catch rate, the oracle's reachable rate, the rate over the reachable throws, the
failures by reason, the hand's error, the peak contact force (the grip's, mostly), the impact
force along the palm's normal and the ball's speed relative to the hand at the impact over its own
(``worlds/catch/outcome.py``), and the arm's largest joint speed over
its limit (the realized one: the simulated plant does not enforce it); ``--compare`` adds rows of other
runs on the same seeds (without velocity matching, at half the time step) and the impact on the
throws caught by both, paired; ``--figure`` writes the
catch rate against the throw's launch speed (the frozen thrower's, bins of 0.25 m/s).

    ptint robust catch_toss_iiwa14 --samples 200 --workers 2 --out out/catch200
    ptint robust catch_toss_iiwa14 --samples 48 --workers 2 --set catch.match=0 --out out/catch_m0
    .venv/bin/python scripts/catch_table.py out/catch200 --compare "m = 0=out/catch_m0" \\
        --figure docs/_static/catch_rate_speed.png
"""

from __future__ import annotations

import argparse
import json
import sys
from collections import Counter
from pathlib import Path

import numpy as np

from ptint_drake.worlds.catch.thrower import throw

HAND_START = np.array([0.5803, -0.0, 0.7262])  # approximately: only the launch speed is read


def _rows(folder: str) -> list:
    path = Path(folder) / "samples.json"
    if not path.is_file():
        raise FileNotFoundError(f"{folder}: no samples.json (a ptint robust output folder)")
    return json.loads(path.read_text())


def _median(values) -> str:
    values = [v for v in values if v is not None]
    return f"{np.median(values):.1f}" if values else "–"


def line(name: str, rows: list) -> str:
    """One markdown row: throws, caught, rate, reachable, caught of reachable, error, force."""
    caught = [r for r in rows if r["outcome"] == "caught"]
    reach = [r for r in rows if r.get("reachable")]
    of_reach = sum(r["outcome"] == "caught" for r in reach)
    return (f"| {name} | {len(rows)} | {len(caught)} ({100 * len(caught) / len(rows):.1f} %) | "
            f"{len(reach)} | {of_reach} ({100 * of_reach / max(len(reach), 1):.1f} %) | "
            f"{_median(r['error_at_catch_mm'] for r in rows)} | "
            f"{_median(r['peak_contact_force_n'] for r in caught)} | "
            f"{_median(r.get('impact_force_n') for r in caught)} | {_relative(caught)} | {_speeds(rows)} |")


def _relative(rows: list) -> str:
    """The ball's speed relative to the hand at the impact over its own speed: the median."""
    values = [r["impact_speed_m_s"] / r["ball_speed_at_impact_m_s"] for r in rows
              if r.get("impact_speed_m_s") is not None and r.get("ball_speed_at_impact_m_s")]
    return f"{np.median(values):.3f}" if values else "–"


def paired(name: str, rows: list, other: list) -> str:
    """The impact force and the relative speed on the throws caught in both runs (with the
    matching: ``rows``; ``other``: the run named ``name``): medians and the per-throw change."""
    a = {r["seed"]: r for r in rows if r["outcome"] == "caught" and r.get("impact_force_n") is not None}
    b = {r["seed"]: r for r in other if r["outcome"] == "caught" and r.get("impact_force_n") is not None}
    both = sorted(set(a) & set(b))
    if not both:
        return f"{name}: no throw caught by both with an impact measured"
    fa, fb = (np.array([x[k]["impact_force_n"] for k in both]) for x in (a, b))
    va, vb = (np.array([x[k]["impact_speed_m_s"] for k in both]) for x in (a, b))
    lower_f, lower_v = 100 * (1 - np.median(fa) / np.median(fb)), 100 * (1 - np.median(va) / np.median(vb))
    return (f"impact on the {len(both)} throws caught by both (default vs {name}): median "
            f"{np.median(fa):.1f} N vs {np.median(fb):.1f} N ({lower_f:.1f} % lower; per throw "
            f"{100 * np.median(1 - fa / fb):.1f} % median); relative speed {np.median(va):.2f} vs "
            f"{np.median(vb):.2f} m/s ({lower_v:.1f} % lower)")


def _speeds(rows: list) -> str:
    """The arm's largest joint speed over its limit per run: median (max), and how many runs > 1."""
    values = [r["joint_speed_ratio_max"] for r in rows if r.get("joint_speed_ratio_max") is not None]
    if not values:
        return "–"
    return f"{np.median(values):.2f} ({max(values):.2f}; {sum(v > 1.0 for v in values)} > 1)"


def failures(rows: list) -> str:
    """The misses by reason, each with its throws (and the oracle's verdict on them)."""
    by = {}
    for r in rows:
        if r["outcome"] != "caught":
            by.setdefault(r["outcome"], []).append(f"{r['seed']}{'' if r.get('reachable') else '*'}")
    counts = Counter({k: len(v) for k, v in by.items()})
    return "\n".join(f"| {k} | {n} | {', '.join(by[k])} |" for k, n in counts.most_common())


def figure(rows: list, path: str) -> None:
    """Catch rate and reachable rate against the launch speed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    speed = np.array([np.linalg.norm(throw(r["params"].get("throw", r["seed"]), HAND_START).velocity)
                      for r in rows])
    caught = np.array([r["outcome"] == "caught" for r in rows])
    reach = np.array([bool(r.get("reachable")) for r in rows])
    edges = np.arange(np.floor(speed.min() * 4) / 4, speed.max() + 0.25, 0.25)
    mid, rate, rrate, count = [], [], [], []
    for lo, hi in zip(edges[:-1], edges[1:]):
        inside = (speed >= lo) & (speed < hi)
        if inside.sum():
            mid.append(0.5 * (lo + hi))
            rate.append(100 * caught[inside].mean())
            rrate.append(100 * reach[inside].mean())
            count.append(int(inside.sum()))
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    ax.bar(mid, rrate, width=0.22, color="0.85", label="oracle: reachable")
    ax.plot(mid, rate, "o-", color="C1", label="caught")
    for x, n in zip(mid, count):
        ax.annotate(f"{n}", (x, 2), ha="center", fontsize=7, color="0.4")
    ax.set_xlabel("launch speed (m/s)")
    ax.set_ylabel("% of the throws in the bin")
    ax.set_ylim(0, 105)
    ax.legend(loc="center left")
    ax.set_title(f"catch rate against throw speed ({len(rows)} throws; bin counts at the bottom)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", help="a ptint robust output folder of a catch scenario")
    parser.add_argument("--compare", action="append", default=[], metavar="NAME=FOLDER",
                        help="another run's folder, its row named NAME (its seeds compared with the first's)")
    parser.add_argument("--figure", help="write the catch rate against the throw speed here (PNG)")
    args = parser.parse_args(argv)
    try:
        rows = _rows(args.folder)
        others = []
        for spec in args.compare:
            if "=" not in spec:
                raise ValueError(f"--compare: expected NAME=FOLDER, got {spec!r}")
            name, folder = spec.rsplit("=", 1)
            others.append((name, _rows(folder)))
    except (FileNotFoundError, ValueError) as exc:
        print(exc, file=sys.stderr)
        return 2
    print("| run | throws | caught | reachable (oracle) | caught of reachable | hand error median (mm) "
          "| peak force median, caught (N) | impact median, caught (N) "
          "| relative / ball speed at the impact, median | joint speed / limit, median (max; runs > 1) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    print(line("default", rows))
    for name, other in others:
        seeds = {r["seed"] for r in other}
        print(line(f"default, the same {len(seeds)} throws", [r for r in rows if r["seed"] in seeds]))
        print(line(name, other))
    for name, other in others:
        print("\n" + paired(name, rows, other))
    print("\n| failure | throws | which (* the oracle: not reachable) |\n|---|---|---|")
    print(failures(rows))
    if args.figure:
        figure(rows, args.figure)
    return 0


if __name__ == "__main__":
    sys.exit(main())
