"""Regenerate the tables of the README and the documentation pages from the commands behind them.

    .venv/bin/python scripts/readme_tables.py            # tuning and the camera study (~30 min)

The results table, the comparisons and every other block a test checks are written by
``scripts/doc_blocks.py``; these two (``tune``, ``camera``) are not checked by a test yet.
Each table sits between ``<!-- BEGIN name -->`` and ``<!-- END name -->`` in README.md and/or
the pages of docs/ (controllers.md, own_controller.md, own_arm.md, camera.md) and is
replaced in place in every file that has it, with the command and the machine it was
measured on.  Timings (realtime
factors, study wall times) depend on the machine; errors and verdicts do not (the runs are
deterministic).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PAGES = [README, *sorted((ROOT / "docs").glob("*.md"))]  # the files whose tables are filled in
PAPER = ("curve_b025_tf15", "curve_b050_tf15", "curve_b075_tf15", "curve_b075_tf12", "curve_b075_tf19",
         "assembly")


def machine() -> str:
    import importlib.metadata as md  # noqa: PLC0415

    return (f"{os.cpu_count()}-core {platform.machine()}, Python {platform.python_version()}, "
            f"Drake {md.version('drake')}")


def mm(v, digits: int = 4) -> str:
    return "–" if v is None else f"{v * 1e3:.{digits}g}"


def tune_table(workers: int) -> str:
    from ptint_drake.scenario import LoadedScenario, scenario_text  # noqa: PLC0415
    from ptint_drake.studies.tune import TuneSettings, run_tune  # noqa: PLC0415

    sys.path.insert(0, str(ROOT / "tests"))
    from heavy_arm import heavy_arm_scenario, heavy_arm_urdf  # noqa: PLC0415

    folder = Path(tempfile.mkdtemp())
    (folder / "heavy6.urdf").write_text(heavy_arm_urdf())
    cases = [(n, scenario_text(n)[1]) for n in PAPER + ("conveyor_pair",)]
    cases.append(("heavy 6-joint arm (tests/heavy_arm.py)", heavy_arm_scenario(folder / "heavy6.urdf")))
    lines = ["| scenario | tuned K (margin 2) | paper's K | e(tf) nominal / ×0.7 / ×1.5 [mm] | runs | time |",
             "|---|---|---|---|---|---|"]
    for name, text in cases:
        r = run_tune(LoadedScenario.parse(text, name.split()[0]), TuneSettings(), workers=workers,
                     say=lambda m: None)
        if r["gains"] is None:
            lines.append(f"| {name} | none works ({', '.join(r['reasons'])}) | {r['paper_value']:g} | – "
                         f"| {r['runs']} | {r['wall_time_s']:.0f} s |")
            continue
        per = r["smallest_working"]["per_variant"]
        errors = " / ".join(mm(per[v]["e_tf_norm"], 3) for v in r["variants"])
        lines.append(f"| {name} | {r['gains']['K']:.3g} | {r['paper_value']:g} | {errors} | {r['runs']} "
                     f"| {r['wall_time_s']:.0f} s |")
    return "\n".join(lines) + f"\n\n`ptint tune NAME --workers {workers}`, on {machine()}.\n"


def camera_table(workers: int) -> str:
    out = Path(tempfile.mkdtemp()) / "study"
    subprocess.run([sys.executable, "-m", "ptint_drake", "study", "camera", "--workers", str(workers),
                    "--out", str(out), "--quiet"], check=True)
    data = json.loads((out / "camera_study.json").read_text())
    text = "\n".join(f"**{line[2:]}**" if line.startswith("# ") else line
                     for line in (out / "camera_study.md").read_text().splitlines())
    return text + "\n" + (
        f"\n`ptint study camera --workers {workers}`: {data['wall_time_s']:.0f} s on {machine()}.\n")


def replace(texts: dict, name: str, table: str) -> dict:
    """``texts`` (path → text) with the block ``name`` replaced by ``table`` wherever it is."""
    pattern = re.compile(rf"(<!-- BEGIN {name} -->\n).*?(<!-- END {name} -->)", re.S)
    found = [path for path, text in texts.items() if pattern.search(text)]
    if not found:
        raise SystemExit(f"no <!-- BEGIN {name} --> … <!-- END {name} --> block in README.md or docs/*.md")
    return {path: pattern.sub(lambda m: m.group(1) + table + m.group(2), text) if path in found else text
            for path, text in texts.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    text = {path: path.read_text() for path in PAGES}
    text = replace(text, "tune", tune_table(args.workers))
    text = replace(text, "camera", camera_table(args.workers))
    for path, content in text.items():
        if content != path.read_text():
            path.write_text(content)
    print(f"README.md and docs/ tables regenerated on {machine()}")


if __name__ == "__main__":
    main()
