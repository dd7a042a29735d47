"""Stills of the replays for the documentation: an interception replay and a pick replay, each
photographed by headless Chromium (playwright) at three times, into docs/_static.

    .venv/bin/python scripts/replay_screenshots.py            # runs the two scenarios, then shoots
    .venv/bin/python scripts/replay_screenshots.py --runs DIR # DIR/<scenario>/replay.html instead

Each page is opened, its animation paused (the overlay's button) and sought to the time
(``viewer.animator.seek``), and the page photographed with its overlay: the time, the legend.
The interception replay is ``assembly`` (three objects, prescribed 0.5, 2.2 and 4.3 s), the pick
replay ``conveyor_pick_place_rgbd`` (the depth camera's point cloud and the part's estimate).
The same pick run's figures are copied beside them (``FIGURES``: picks.png, estimates.png and the
camera's frames at the first fit), as the documentation's stills of each, and ``FIGURE_RUNS``' (a
retry's picks.png).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
STATIC = ROOT / "docs" / "_static"
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
BROWSER_ARGS = ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                "--no-first-run"]
# scenario → (file stem, the three times [s]); the pick's middle time is inside its first fit's
# cloud interval (shown from the first fit, ~0.03 s, until the grasp's frame, 1.7 s)
SHOTS = {"assembly": ("replay_assembly", (0.3, 2.2, 4.6)),
         "conveyor_pick_place_rgbd": ("replay_pick_rgbd", (0.2, 1.0, 3.0))}
# a run's file → the still in docs/_static
FIGURES = {"conveyor_pick_place_rgbd": {"picks.png": "picks_rgbd.png", "estimates.png": "estimates_rgbd.png",
                                        "frames/pick0_first_fit_color.png": "frame_first_fit_color.png",
                                        "frames/pick0_first_fit_depth.png": "frame_first_fit_depth.png"}}
# a still of a figure from a run of its own: still → (scenario, --set assignments, the run's file)
FIGURE_RUNS = {"pick_retry.png": ("conveyor_pick_place", ["pick.test_close_advance_s=0.3"], "picks.png")}


def shoot(page_file: Path, times: tuple, stem: str, folder: Path, size: tuple = (1000, 650)) -> list[Path]:
    """Photograph ``page_file`` paused at each of ``times``; returns the PNGs
    (``folder/STEM_t{time}.png``).  Raises on a page error."""
    from playwright.sync_api import sync_playwright  # noqa: PLC0415

    errors, written = [], []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=BROWSER_ARGS)
        page = browser.new_page(viewport={"width": size[0], "height": size[1]})
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(page_file.as_uri())
        page.wait_for_function("window.viewer && viewer.animator && viewer.animator.actions.length > 0",
                               timeout=60_000)
        page.click("#ptint-play")  # pause
        for t in times:
            page.evaluate(f"viewer.animator.seek({t}); viewer.set_dirty()")
            page.wait_for_timeout(800)
            path = folder / f"{stem}_t{t:.1f}.png"
            page.screenshot(path=str(path))
            written.append(path)
        browser.close()
    if errors:
        raise RuntimeError(f"{page_file}: {errors}")
    return written


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, help="read DIR/<scenario>/replay.html instead of running")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        base = args.runs or Path(tmp)
        for name, (stem, times) in SHOTS.items():
            if not args.runs:
                figures = [] if name in FIGURES else ["--no-figures"]
                subprocess.run([sys.executable, "-m", "ptint_drake", "run", name, "--quiet", *figures,
                                "--out", str(base / name)], check=True, capture_output=True)
            for path in shoot(base / name / "replay.html", times, stem, STATIC):
                print(f"wrote {path.relative_to(ROOT)}")
            for source, still in FIGURES.get(name, {}).items():
                shutil.copyfile(base / name / source, STATIC / still)
                print(f"wrote docs/_static/{still}")
        for still, (name, assignments, source) in FIGURE_RUNS.items():
            sets = [a for assignment in assignments for a in ("--set", assignment)]
            # exit 1 is a run that misses (this one retries and places: exit 0)
            subprocess.run([sys.executable, "-m", "ptint_drake", "run", name, "--quiet", "--no-replay", *sets,
                            "--out", str(Path(tmp) / still)], check=True, capture_output=True)
            shutil.copyfile(Path(tmp) / still / source, STATIC / still)
            print(f"wrote docs/_static/{still}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
