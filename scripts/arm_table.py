"""The per-arm table of docs/own_arm.md (issue 45): each bundled industrial arm's gains and what its
three worlds measure — the curve's e(tf), the pose task's e(tf) and angle, the pick's place errors
and each run's realtime factor.

    .venv/bin/python scripts/arm_table.py              # runs the nine scenarios (~4 min, one at a time)
    .venv/bin/python scripts/arm_table.py --runs DIR   # reads DIR/<scenario>/metrics.json instead
    .venv/bin/python scripts/arm_table.py --check      # exit 1 if the block's gains differ from the files

The block between ``<!-- BEGIN arms -->`` and ``<!-- END arms -->`` is replaced.  Its first table
(gains, grippers) comes from the scenario files alone, so ``--check`` compares it exactly without a
simulation; the second (measurements) is checked to list the same scenarios (its numbers need the
runs).  Sources of every model parameter: models/README.md.
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "own_arm.md"
ARMS = ("iiwa14", "panda", "ur5e")
WORLDS = ("curve", "pose", "pick")
BEGIN, END = "<!-- BEGIN arms -->", "<!-- END arms -->"
# where each scenario's K comes from (the scenario files' comments say the same, with the tune's numbers)
K_SOURCE = {"curve_iiwa14": "`ptint tune curve_iiwa14`",
            "pose_iiwa14": "curve_iiwa14's (its own tune: 0.97×)",
            "pick_iiwa14": "curve_iiwa14's (the paper's 50 misses)",
            "curve_panda": "`ptint tune curve_panda`",
            "pose_panda": "`ptint tune pose_panda` (= curve_panda's)", "pick_panda": "the paper's",
            "curve_ur5e": "`ptint tune curve_ur5e`", "pose_ur5e": "`ptint tune pose_ur5e`",
            "pick_ur5e": "the paper's"}


def gains_table() -> str:
    """Per arm and world: K, Λ, k, the null-space damping, rot_scale and the gripper (scenario files)."""
    from ptint_drake.simulation.scenario import load_scenario  # noqa: PLC0415  (pydrake: only when needed)

    rows = ["| scenario | K | K from | Λ, k | null-space D | task (rot_scale) | end effector / gripper |",
            "|---|---|---|---|---|---|---|"]
    for arm in ARMS:
        for world in WORLDS:
            s = load_scenario(f"{world}_{arm}")
            c = s.controller
            task = c.task if c.task == "position" else f"{c.task} ({c.rot_scale:g} m/rad)"
            hand = s.robot.end_effector
            if s.pick is not None:
                hand = f"{hand} / {s.pick.gripper.model}"
            name = f"{world}_{arm}"
            rows.append(f"| {name} | {c.K:g} | {K_SOURCE[name]} | {c.Lambda:g}, {c.k:g} (the paper's) | "
                        f"{c.null_space_damping:g} | {task} | {hand} |")
    return "\n".join(rows)


def run(name: str, out: Path) -> dict:
    """``ptint run NAME`` once; its metrics."""
    subprocess.run([sys.executable, "-m", "ptint_drake", "run", name, "--no-replay", "--no-figures",
                    "--quiet", "--out", str(out)], capture_output=True, text=True, check=False)
    return json.loads((out / "metrics.json").read_text())


def _places(m: dict) -> str:
    mm = max(p["place_error_mm"] for p in m["picks"])
    deg = max(p["place_error_deg"] for p in m["picks"])
    placed = sum(bool(p["placed"]) and not p["collision"] for p in m["picks"])
    return f"{placed}/{len(m['picks'])} placed, worst {mm:.2f} mm / {deg:.2f}°"


def measured_table(results: dict) -> str:
    """Per arm: curve e(tf), pose e(tf) and angle, pick place errors, each with its realtime factor."""
    rows = ["| arm | curve e(tf) (RTF) | pose e(tf), angle (RTF) | pick: parts placed, worst error (RTF) | "
            "verdicts |", "|---|---|---|---|---|"]
    for arm in ARMS:
        c, p, k = (results[f"{w}_{arm}"] for w in WORLDS)
        rtf = {name: m["sim"]["realtime_factor"] for name, m in (("c", c), ("p", p), ("k", k))}
        cs, ps = c["segments"][0], p["segments"][0]
        rows.append(f"| {arm} | {cs['e_tf_norm'] * 1e3:.3f} mm ({rtf['c']:.1f}) | "
                    f"{ps['e_tf_norm'] * 1e3:.3f} mm, {ps['e_rot_tf_deg']:.3f}° ({rtf['p']:.1f}) | "
                    f"{_places(k)} ({rtf['k']:.2f}) | {c['status']} / {p['status']} / {k['status']} |")
    return "\n".join(rows)


def block(results: dict) -> str:
    note = (f"`python scripts/arm_table.py` on {platform.machine()}, Python {platform.python_version()}, "
            f"Drake {version('drake')}; "
            "RTF = simulated / wall-clock time, end to end (> 1: faster than real time). Every model "
            "parameter's source: models/README.md.")
    return f"{BEGIN}\n{gains_table()}\n\n{measured_table(results)}\n\n{note}\n{END}"


def current_block() -> str:
    text = PAGE.read_text()
    match = re.search(re.escape(BEGIN) + ".*?" + re.escape(END), text, re.S)
    return match.group(0) if match else ""


def check() -> int:
    """0 when the page's block holds the files' gains table and a measured row per arm."""
    have = current_block()
    if not have:
        print(f"{PAGE.name}: no {BEGIN} block")
        return 1
    if gains_table() not in have:
        print(f"{PAGE.name}: the arms block's gains differ from the scenario files: run scripts/arm_table.py")
        return 1
    missing = [arm for arm in ARMS if not re.search(rf"^\| {arm} \| [0-9.]+ mm", have, re.M)]
    if missing:
        print(f"{PAGE.name}: the arms block has no measured row for {', '.join(missing)}")
        return 1
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=Path, help="read DIR/<scenario>/metrics.json instead of running")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "arm_table")
    parser.add_argument("--check", action="store_true", help="compare the page's block, run nothing")
    args = parser.parse_args(argv)
    if args.check:
        return check()
    names = [f"{w}_{arm}" for arm in ARMS for w in WORLDS]
    if args.runs:
        results = {n: json.loads((args.runs / n / "metrics.json").read_text()) for n in names}
    else:
        results = {n: run(n, args.out / n) for n in names}
    text = PAGE.read_text()
    new = block(results)
    if current_block():
        text = text.replace(current_block(), new)
    else:
        text = text.rstrip("\n") + "\n\n" + new + "\n"
    PAGE.write_text(text)
    print(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
