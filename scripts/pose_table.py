"""The table of the documentation page on intercepting a pose (docs/pose.md, issue 19):
``conveyor_yaw`` on the nominal plant
and with every link's mass × 0.7 and × 1.5 — distance and angle at tf/2, at tf and the hold's
largest, per segment.

    .venv/bin/python scripts/pose_table.py              # runs the three variants (~6 min, 2 at a time)
    .venv/bin/python scripts/pose_table.py --runs DIR   # reads DIR/<variant>/metrics.json instead

The table is replaced in docs/pose.md between ``<!-- BEGIN pose -->`` and ``<!-- END pose -->``.
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


def folder(variant: str) -> str:
    return {"nominal": "nominal", "mass ×0.7": "mass_x0.7", "mass ×1.5": "mass_x1.5"}[variant]


def run(variant: str, out: Path) -> dict:
    """``ptint run conveyor_yaw`` on one variant; its metrics."""
    subprocess.run([sys.executable, "-m", "ptint_drake", "run", "conveyor_yaw", "--no-replay",
                    "--no-figures", "--quiet", "--out", str(out), *VARIANTS[variant]],
                   capture_output=True, text=True, check=False)
    return json.loads((out / "metrics.json").read_text())


def cell(seg: dict, distance: str, angle: str) -> str:
    return f"{seg[distance] * 1e3:.3g} mm / {seg[angle]:.3g}°"


def table(results: dict) -> str:
    rows = ["| plant | part (yaw) | e(tf/2) | e(tf) | hold max | verdict |", "|---|---|---|---|---|---|"]
    for variant, metrics in results.items():
        for i, (seg, yaw) in enumerate(zip(metrics["segments"], ("0°", "30°", "−45°"))):
            rows.append(f"| {variant} | {i} ({yaw}) | {cell(seg, 'e_half_norm', 'e_rot_half_deg')} | "
                        f"{cell(seg, 'e_tf_norm', 'e_rot_tf_deg')} | "
                        f"{cell(seg, 'e_hold_max_norm', 'e_rot_hold_max_deg')} | {metrics['status']} |")
    note = "`python scripts/pose_table.py` (distance / angle of the gripper to the part)."
    return "\n".join(rows) + "\n\n" + note


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, help="read DIR/<variant>/metrics.json instead of running")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "pose_table")
    args = parser.parse_args()
    if args.runs:
        results = {v: json.loads((args.runs / folder(v) / "metrics.json").read_text()) for v in VARIANTS}
    else:
        with ThreadPoolExecutor(2) as pool:
            done = {v: pool.submit(run, v, args.out / folder(v)) for v in VARIANTS}
        results = {v: f.result() for v, f in done.items()}
    text = table(results)
    print(text)
    page = PAGE.read_text()
    block = f"<!-- BEGIN pose -->\n{text}\n<!-- END pose -->"
    PAGE.write_text(re.sub(r"<!-- BEGIN pose -->.*?<!-- END pose -->", lambda _: block, page, flags=re.S))
    return 0


if __name__ == "__main__":
    sys.exit(main())
