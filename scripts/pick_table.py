"""The pick-and-place table and still (issue 20): ``conveyor_pick_place`` and ``assembly_pick_place``
run with ``ptint run``; one row per pick, and each run's realtime factor.

    .venv/bin/python scripts/pick_table.py              # runs both scenarios (~1 min)
    .venv/bin/python scripts/pick_table.py --runs DIR   # reads DIR/<scenario>/metrics.json instead
    .venv/bin/python scripts/pick_table.py --still      # also docs/_static/pick_grasp.png

The table is replaced between ``<!-- BEGIN picks -->`` and ``<!-- END picks -->`` in every file
that has those markers (README.md, docs/pick_place.md).  The still is the world at the second
pick's prescribed grasp time of ``assembly_pick_place`` (the run's logged plant state drawn by
Meshcat, saved as a page, photographed by headless Chromium).
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FILES = [ROOT / "README.md", ROOT / "docs" / "pick_place.md"]
SCENARIOS = ("conveyor_pick_place", "assembly_pick_place")


def run(name: str, out: Path) -> dict:
    """``ptint run NAME`` (no replay, no figures); its metrics."""
    subprocess.run([sys.executable, "-m", "ptint_drake", "run", name, "--no-replay", "--no-figures",
                    "--quiet", "--out", str(out)], capture_output=True, text=True, check=False)
    return json.loads((out / "metrics.json").read_text())


def table(metrics: dict) -> str:
    """The markdown table of the runs' picks."""
    lines = ["| scenario | pick | part → slot | t_grasp (prescribed) [s] | placed | place error [mm, °] "
             "| slip [mm] | peak grip [N] | realtime factor |", "|---|---|---|---|---|---|---|---|---|"]
    for name, m in metrics.items():
        for k, p in enumerate(m["picks"]):
            prescribed = p["t_grasp_prescribed"]
            grasp = "never" if p["t_grasp"] is None else f"{p['t_grasp']:.3f} ({prescribed:.3f})"
            rtf = f"{m['sim']['realtime_factor']:.2f}" if k == 0 else ""
            lines.append(f"| {name if k == 0 else ''} | {k} | {p['part']} → {p['slot']} | {grasp} | "
                         f"{'yes' if p['placed'] else 'NO'} | "
                         f"{p['place_error_mm']:.2f}, {p['place_error_deg']:.2f} "
                         f"| {p['slip_mm']:.2f} | {p['peak_grip_force_N']:.0f} | {rtf} |")
    from importlib.metadata import version  # noqa: PLC0415

    lines.append("")
    lines.append(f"Measured by `scripts/pick_table.py` on {platform.machine()}, Python "
                 f"{platform.python_version()}, Drake {version('drake')}; the realtime factor (end to "
                 f"end) depends on the machine and its load.")
    return "\n".join(lines)


def replace(block: str, name: str = "picks") -> None:
    """Put ``block`` between the ``name`` markers of every file in FILES that has them."""
    begin, end = f"<!-- BEGIN {name} -->", f"<!-- END {name} -->"
    for path in FILES:
        text = path.read_text()
        if begin in text:
            new = f"{begin}\n{block}\n{end}"
            path.write_text(re.sub(f"{begin}.*?{end}", lambda _: new, text, flags=re.S))


def still(path: Path) -> None:
    """The assembly's world at its second pick's prescribed grasp time, as a PNG."""
    import numpy as np  # noqa: PLC0415

    from ptint_drake.worlds.pick.views import replay_world  # noqa: PLC0415
    from ptint_drake.replay import CAMERA, with_camera  # noqa: PLC0415
    from ptint_drake.scenario import load_scenario  # noqa: PLC0415
    from ptint_drake.simulation import simulate  # noqa: PLC0415

    scenario = load_scenario("assembly_pick_place")
    result = simulate(scenario)
    t_grasp = result.metrics["picks"][1]["t_grasp_prescribed"]
    plant, viz, meshcat, context = replay_world(scenario)
    j = int(np.argmin(np.abs(result.series["replay_t"] - t_grasp)))
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context),
                       result.series["plant_state"][j, :plant.num_positions()])
    viz.ForcedPublish(viz.GetMyContextFromRoot(context))
    html = with_camera(meshcat.StaticHtml(), (0.55, -0.35, 0.45))
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    with tempfile.TemporaryDirectory() as tmp:
        page = Path(tmp) / "still.html"
        page.write_text(html, encoding="utf-8")
        subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                        f"--screenshot={path}", "--window-size=900,600", "--virtual-time-budget=5000",
                        page.as_uri()], capture_output=True, check=True, timeout=120)
    print(f"wrote {path} (t = {result.series['replay_t'][j]:.3f} s, camera {CAMERA} → a closer view)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, help="read DIR/<scenario>/metrics.json instead of running")
    parser.add_argument("--still", action="store_true", help="also write docs/_static/pick_grasp.png")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = args.runs or Path(tmp)
        read = lambda n: json.loads((base / n / "metrics.json").read_text())  # noqa: E731
        metrics = {n: read(n) if args.runs else run(n, base / n) for n in SCENARIOS}
        replace(table(metrics))
    if args.still:
        still(ROOT / "docs" / "_static" / "pick_grasp.png")
    print("pick table regenerated")


if __name__ == "__main__":
    main()
