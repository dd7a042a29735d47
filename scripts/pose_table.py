"""The tables of the documentation page on intercepting a pose (docs/pose.md, issue 19):
``conveyor_yaw`` and ``curve_pose`` on the nominal plant and with every link's mass × 0.7 and
× 1.5 — distance and angle at tf/2, at tf and the hold's largest, per segment.

    .venv/bin/python scripts/pose_table.py              # runs the six runs (~7 min, 2 at a time)
    .venv/bin/python scripts/pose_table.py --runs DIR   # reads DIR/<scenario>/<variant>/metrics.json instead

The tables are replaced in docs/pose.md between ``<!-- BEGIN pose -->`` and ``<!-- END pose -->``.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "pose.md"
VARIANTS = {"nominal": [], "mass ×0.7": ["--set", "plant.mass_scale=0.7"],
            "mass ×1.5": ["--set", "plant.mass_scale=1.5"]}
# scenario → (the segment column's title, each segment's label)
SCENARIOS = {"conveyor_yaw": ("part (yaw)", ("0 (0°)", "1 (30°)", "2 (−45°)")),
             "curve_pose": ("segment", ("0 (curve, tumbling)",))}


def folder(variant: str) -> str:
    return {"nominal": "nominal", "mass ×0.7": "mass_x0.7", "mass ×1.5": "mass_x1.5"}[variant]


def run(scenario: str, variant: str, out: Path) -> dict:
    """``ptint run SCENARIO`` on one variant; its metrics."""
    subprocess.run([sys.executable, "-m", "ptint_drake", "run", scenario, "--no-replay",
                    "--no-figures", "--quiet", "--out", str(out), *VARIANTS[variant]],
                   capture_output=True, text=True, check=False)
    return json.loads((out / "metrics.json").read_text())


def cell(seg: dict, distance: str, angle: str) -> str:
    return f"{seg[distance] * 1e3:.3g} mm / {seg[angle]:.3g}°"


def table(scenario: str, results: dict) -> str:
    """One scenario's rows: variant × segment."""
    title, labels = SCENARIOS[scenario]
    rows = [f"| plant | {title} | e(tf/2) | e(tf) | hold max | verdict |", "|---|---|---|---|---|---|"]
    for variant, metrics in results.items():
        for seg, label in zip(metrics["segments"], labels):
            rows.append(f"| {variant} | {label} | {cell(seg, 'e_half_norm', 'e_rot_half_deg')} | "
                        f"{cell(seg, 'e_tf_norm', 'e_rot_tf_deg')} | "
                        f"{cell(seg, 'e_hold_max_norm', 'e_rot_hold_max_deg')} | {metrics['status']} |")
    return "\n".join(rows)


def tables(results: dict) -> str:
    """Both scenarios' tables, each under its name, and how they were made."""
    parts = [f"`{name}`:\n\n{table(name, by_variant)}" for name, by_variant in results.items()]
    note = "`python scripts/pose_table.py` (distance / angle of the gripper to the part)."
    return "\n\n".join(parts) + "\n\n" + note


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path,
                        help="read DIR/<scenario>/<variant>/metrics.json instead of running")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "pose_table")
    args = parser.parse_args()
    if args.runs:
        results = {s: {v: json.loads((args.runs / s / folder(v) / "metrics.json").read_text())
                       for v in VARIANTS} for s in SCENARIOS}
    else:
        with ThreadPoolExecutor(2) as pool:
            done = {s: {v: pool.submit(run, s, v, args.out / s / folder(v)) for v in VARIANTS}
                    for s in SCENARIOS}
        results = {s: {v: f.result() for v, f in futures.items()} for s, futures in done.items()}
    text = tables(results)
    print(text)
    page = PAGE.read_text()
    block = f"<!-- BEGIN pose -->\n{text}\n<!-- END pose -->"
    PAGE.write_text(re.sub(r"<!-- BEGIN pose -->.*?<!-- END pose -->", lambda _: block, page, flags=re.S))
    return 0


if __name__ == "__main__":
    sys.exit(main())
