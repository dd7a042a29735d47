"""The camera pick gate of issue 34 over seeds: every part placed, the place error and the
estimate's error at the grasp (median / p90 / max), as JSON on stdout.

    python scripts/rgbd_pick_table.py --seeds 1-10 [--scenarios conveyor_pick_place_rgbd,...]
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from ptint_drake.scenario import load_scenario, parse_with_overrides, scenario_text
from ptint_drake.simulation import simulate

FIELDS = ("place_error_mm", "place_error_deg", "estimate_error_mm", "estimate_error_deg")


def _spread(values: list) -> dict:
    a = np.asarray([v for v in values if v is not None], dtype=float)
    if a.size == 0:
        return {}
    return {"median": float(np.median(a)), "p90": float(np.percentile(a, 90)), "max": float(a.max())}


def gate(name: str, seeds: list[int]) -> dict:
    """One scenario over ``seeds``: runs ok, parts placed, the spreads of ``FIELDS``."""
    _, text = scenario_text(name)
    picks, ok = [], 0
    for seed in seeds:
        metrics = simulate(parse_with_overrides(text, f"measurement: {{seed: {seed}}}", name)).metrics
        ok += metrics["status"] == "ok"
        picks += metrics["picks"]
    return {"scenario": name, "seeds": seeds, "runs_ok": ok,
            "placed": sum(bool(p["placed"]) for p in picks), "parts": len(picks),
            **{f: _spread([p.get(f) for p in picks]) for f in FIELDS}}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="1-10")
    parser.add_argument("--scenarios", default="conveyor_pick_place_rgbd,assembly_pick_place_rgbd")
    args = parser.parse_args()
    lo, _, hi = args.seeds.partition("-")
    seeds = list(range(int(lo), int(hi or lo) + 1))
    load_scenario("conveyor_pick_place_rgbd")  # fail early on a broken install
    print(json.dumps([gate(n, seeds) for n in args.scenarios.split(",")], indent=1))


if __name__ == "__main__":
    main()
