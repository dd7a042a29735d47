"""The camera pick gate of issue 34 over seeds: every part placed, the place error and the
estimate's error at the grasp (median / p90 / max), as JSON on stdout.

    python scripts/rgbd_pick_table.py --seeds 1-10 [--scenarios conveyor_pick_place_rgbd,...]
    python scripts/rgbd_pick_table.py --seeds 1-10 --write   # also docs/_data/rgbd_picks.json

``--write`` stores the output with its stamp as docs/_data/rgbd_picks.json, which
``scripts/doc_blocks.py`` renders into docs/camera.md's ``rgbd_picks`` block.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import load_scenario, parse_with_overrides, scenario_text

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
    parser.add_argument("--write", action="store_true", help="also write docs/_data/rgbd_picks.json")
    args = parser.parse_args()
    lo, _, hi = args.seeds.partition("-")
    seeds = list(range(int(lo), int(hi or lo) + 1))
    load_scenario("conveyor_pick_place_rgbd")  # fail early on a broken install
    gates = [gate(n, seeds) for n in args.scenarios.split(",")]
    print(json.dumps(gates, indent=1))
    if args.write:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        from doc_blocks import DATA, stamp  # noqa: PLC0415

        (DATA / "rgbd_picks.json").write_text(json.dumps(
            {"source": f"`scripts/rgbd_pick_table.py --seeds {args.seeds}`, {stamp()}", "gates": gates},
            indent=1) + "\n")


if __name__ == "__main__":
    main()
