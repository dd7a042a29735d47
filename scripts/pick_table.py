"""The pick-and-place table and still (issue 20): ``conveyor_pick_place`` and ``assembly_pick_place``
run with ``ptint run``; one row per pick, and each run's realtime factor.

    .venv/bin/python scripts/pick_table.py              # runs both scenarios (~1 min)
    .venv/bin/python scripts/pick_table.py --still      # also docs/_static/pick_grasp.png

The table (the block ``picks`` of README.md and docs/pick_place.md) is written by
``scripts/doc_blocks.py picks``, which this calls; tests/e2e/test_doc_blocks_runs.py checks it.
The still is the world at the second
pick's prescribed grasp time of ``assembly_pick_place`` (the run's logged plant state drawn by
Meshcat, saved as a page, photographed by headless Chromium).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FILES = [ROOT / "README.md", ROOT / "docs" / "pick_place.md"]
SCENARIOS = ("conveyor_pick_place", "assembly_pick_place")


def still(path: Path) -> None:
    """The assembly's world at its second pick's prescribed grasp time, as a PNG."""
    import numpy as np  # noqa: PLC0415

    from ptint_drake.simulation import simulate  # noqa: PLC0415
    from ptint_drake.simulation.scenario import load_scenario  # noqa: PLC0415
    from ptint_drake.views.replay import CAMERA, with_camera  # noqa: PLC0415
    from ptint_drake.worlds.pick.views import draw_pick_floor, replay_world  # noqa: PLC0415

    scenario = load_scenario("assembly_pick_place")
    result = simulate(scenario)
    t_grasp = result.metrics["picks"][1]["t_grasp_prescribed"]
    plant, viz, meshcat, context = replay_world(scenario)
    j = int(np.argmin(np.abs(result.series["replay_t"] - t_grasp)))
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context),
                       result.series["plant_state"][j, :plant.num_positions()])
    draw_pick_floor(meshcat, plant, context)  # the floor, Meshcat's grid and axes hidden (as the replay)
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
    parser.add_argument("--still", action="store_true", help="also write docs/_static/pick_grasp.png")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / "scripts"))
    from doc_blocks import main as write_blocks  # noqa: PLC0415

    write_blocks(["picks"])
    if args.still:
        still(ROOT / "docs" / "_static" / "pick_grasp.png")
    print("pick table regenerated")


if __name__ == "__main__":
    main()
