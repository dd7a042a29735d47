"""Issue 45's long pick sequence on a 7-joint arm: ≥ 20 picks in about 60 s spanning ≥ 120° of base
rotation, run with the null-space posture task and without it (``null_space_damping: 0``).

    .venv/bin/python scripts/posture_sequence.py iiwa14 [--out DIR]   # two runs of ~60 s simulated
    .venv/bin/python scripts/posture_sequence.py panda --write-only    # only the scenario file
    .venv/bin/python scripts/posture_sequence.py panda --report-only   # the report of runs in DIR

The world: two belts at 0.1 m/s on either side of the arm (base azimuths −60° and +60°, running
across the arm's reach), each with ten parts, and a tray beside each (−30° and +30°); the first ten
tasks pick from the first belt into the first tray, the last ten from the second into the second,
so the base turns through 120° and back.  Every task's segments are shortened (``TFS``) to fit 20
picks in the time.  The rest posture (``null_space_posture_deg``) faces the tray (joint 1 at 0); the
arm starts from it turned to the first belt; the posture task also pushes joints back from their
limits (``null_space_limit_margin_deg``).

Writes ``DIR/sequence_ARM.yaml`` and, per variant, ``DIR/<variant>/metrics.json``, then
``DIR/posture.png`` (the posture error |q − q_rest| over time of both runs beside each other, and
each joint's smallest distance to its limit) and ``DIR/report.json``: picks placed, worst place error,
the posture error's maximum, the closest approach to a joint limit, per variant.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
# per arm: (rest posture [deg], K, gripper, belt radius, belt height, tray radius, tray height)
ARMS = {"iiwa14": ([0.0, 30.0, 0.0, -80.0, 0.0, 60.0, 0.0], 150.0, "schunk_wsg_50_110_full", 0.6, 0.20, 0.6,
                   0.22),
        "panda": ([0.0, -20.0, 0.0, -120.0, 0.0, 100.0, 45.0], 100.0, "panda_hand", 0.5, 0.20, 0.5, 0.22)}
START_J1 = -60.0  # deg: the start posture is the rest posture turned to the first belt
TFS = {"approach": 0.8, "descend": 0.3, "lift": 0.25, "carry": 0.8, "place": 0.3, "retreat": 0.25}
DWELL = 0.1  # s (default 0.15; the grip builds up within 30 ms)
SWITCH_APPROACH = 1.6  # s: the approach that crosses from one side to the other
PER_SIDE = 10
SIDES = (-60.0, 60.0)  # deg: the belts' base azimuths; the trays at half of it
SPEED = 0.1  # m/s
LIMIT_MARGIN_DEG = 20.0
VARIANTS = {"posture": 10.0, "no_posture": 0.0}  # null_space_damping


def _task_time() -> float:
    return sum(TFS.values()) + 2 * DWELL


def scenario(arm: str) -> str:
    """The scenario's YAML text (module docstring)."""
    q0, K, gripper, r_belt, z_belt, r_tray, z_tray = ARMS[arm]
    belts, parts, trays, tasks = [], [], [], []
    period = _task_time()
    for s, az in enumerate(SIDES):
        a = math.radians(az)
        centre = [r_belt * math.cos(a), r_belt * math.sin(a), z_belt]
        # across the reach, both flowing from behind the arm to its front (their far ends cross in
        # front of it, past the picks: no part rides over the other belt)
        direction = [abs(math.sin(a)), -math.copysign(math.cos(a), a), 0.0]
        dirs = "[" + ", ".join(f"{v:.15g}" for v in direction) + "]"
        belts.append(f"    - {{name: belt{s}, center: {_v(centre)}, direction: {dirs}, speed: {SPEED},"
                     f" width: 0.06, length: 14.0}}")
        t = math.radians(az / 2)
        slots = [f"{{offset: [{dx:.4f}, {dy:.4f}]}}" for dy in (-0.14, -0.07, 0.0, 0.07, 0.14)
                 for dx in (-0.035, 0.035)]
        trays.append((f"tray{s}", [r_tray * math.cos(t), r_tray * math.sin(t), z_tray], az / 2, slots))
        for j in range(PER_SIDE):
            k = s * PER_SIDE + j
            extra = SWITCH_APPROACH - TFS["approach"] if k >= PER_SIDE else 0.0
            grasp = k * period + extra + TFS["approach"] + TFS["descend"]
            tfs = dict(TFS, approach=SWITCH_APPROACH) if k == PER_SIDE else TFS
            yaw = (15.0, 30.0, -45.0, 0.0, -20.0)[k % 5]
            parts.append(f"    - {{name: part{k}, belt: belt{s}, size: [0.03, 0.03, 0.03], "
                         f"offset: {-SPEED * grasp:.4f}, yaw_deg: {yaw}}}")
            moves = ", ".join(f"{p}: {{tf: {v}}}" for p, v in tfs.items())
            tasks.append(f"    - {{part: part{k}, slot: {k}, dwell: {DWELL}, {moves}}}")
    duration = 60.0  # 20 tasks of 2.9 s, then the arm holds over the tray
    return "\n".join([
        f"# Issue 45: {2 * PER_SIDE} picks in {duration:g} s spanning {SIDES[1] - SIDES[0]:g}° of base "
        f"rotation on {arm} (scripts/posture_sequence.py writes this file).",
        f"duration: {duration}", "robot:", f"  model: {arm}", f"  end_effector: {gripper}_tip",
        f"  initial_q_deg: {_v([START_J1] + q0[1:])}",
        f"controller: {{K: {K}, task: top_down, rot_scale: 0.1, control_period: 0.001,",
        f"             null_space_damping: 10.0, null_space_posture_deg: {_v(q0)},",
        f"             null_space_limit_margin_deg: {LIMIT_MARGIN_DEG}}}",
        "multibody: {time_step: 0.001, contact_model: point, discrete_contact_approximation: sap}",
        "pick:", f"  gripper: {{model: {gripper}}}", "  belts:", *belts, "  parts:", *parts, *_trays(trays),
        "  tasks:", *tasks]) + "\n"


def _trays(trays: list) -> list:
    """One tray only is supported by the pick world: both groups of slots on one tray would be far
    apart, so the tray spans both sides (its slots at the two azimuths)."""
    (_, c0, y0, s0), (_, c1, y1, s1) = trays
    centre = [(c0[0] + c1[0]) / 2, (c0[1] + c1[1]) / 2, c0[2]]
    out = []
    for c, slots in ((c0, s0), (c1, s1)):
        for slot in slots:
            dx, dy = (float(v) for v in slot[slot.index("[") + 1:slot.index("]")].split(","))
            out.append(f"{{offset: [{c[0] - centre[0] + dx:.4f}, {c[1] - centre[1] + dy:.4f}]}}")
    width = abs(c1[1] - c0[1]) + 0.35
    return ["  tray:", f"    center: {_v(centre)}", f"    size: [0.16, {width:.3f}, 0.01]",
            "    slots: [" + ", ".join(out) + "]"]


def _v(values) -> str:
    return "[" + ", ".join(f"{float(v):.4f}" for v in values) + "]"


def posture_error(q: np.ndarray, q_rest: np.ndarray) -> np.ndarray:
    """|q − q_rest| (deg) per sample, q as (n, samples) or (samples, n)."""
    q = q if q.shape[0] != q_rest.size else q.T
    return np.degrees(np.linalg.norm(q - q_rest, axis=1))


def limit_margin(arm: str, q: np.ndarray) -> np.ndarray:
    """Per joint, the smallest distance to either position limit over the run (deg)."""
    from pydrake.multibody.parsing import Parser  # noqa: PLC0415
    from pydrake.multibody.plant import MultibodyPlant  # noqa: PLC0415

    from ptint_drake.robot.rvm1 import model_path  # noqa: PLC0415

    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path(arm)))
    plant.Finalize()
    lo, hi = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    q = q if q.shape[-1] == lo.size else q.T
    return np.degrees(np.minimum(q - lo, hi - q).min(axis=0))


def run_variant(path: Path, out: Path, damping: float) -> int:
    cmd = [sys.executable, "-m", "ptint_drake", "run", str(path), "--no-replay", "--no-figures", "--quiet",
           "--out", str(out), "--set", f"controller.null_space_damping={damping}"]
    return subprocess.run(cmd, check=False).returncode


def _row(m: dict, err: np.ndarray, margins: np.ndarray) -> dict:
    picks = m["picks"]
    return {"status": m["status"], "placed": sum(bool(p["placed"]) and not p["collision"] for p in picks),
            "picks": len(picks), "worst_place_mm": max(p["place_error_mm"] for p in picks),
            "worst_place_deg": max(p["place_error_deg"] for p in picks),
            "posture_error_max_deg": float(err.max()), "limit_margin_min_deg": margins.round(1).tolist(),
            "realtime_factor": m["sim"]["realtime_factor"]}


def report(arm: str, out: Path) -> dict:
    """Per variant: picks placed, worst place error, posture error max, limit margins; and the figure."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    q_rest = np.radians(ARMS[arm][0])
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), sharey=True)
    rows = {}
    for ax, name in zip(axes, VARIANTS):
        m = json.loads((out / name / "metrics.json").read_text())
        series = np.load(out / name / "series.npz")
        err = posture_error(series["q"], q_rest)
        t = series["t"] if "t" in series else np.linspace(0.0, m["duration"], err.size)
        rows[name] = _row(m, err, limit_margin(arm, series["q"]))
        q = series["q"] if series["q"].shape[-1] == q_rest.size else series["q"].T
        rows[name]["base_rotation_span_deg"] = float(np.degrees(q[:, 0].max() - q[:, 0].min()))
        picks = m["picks"]
        ax.plot(t[: err.size], err)
        ax.set_title(f"{arm}, {name.replace('_', ' ')}: max {err.max():.1f}°, "
                     f"{rows[name]['placed']}/{len(picks)} placed")
        ax.set_xlabel("t [s]")
    axes[0].set_ylabel("|q − q_rest| [deg]")
    fig.tight_layout()
    fig.savefig(out / "posture.png", dpi=110)
    (out / "report.json").write_text(json.dumps(rows, indent=1))
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("arm", choices=sorted(ARMS))
    parser.add_argument("--out", type=Path)
    parser.add_argument("--write-only", action="store_true")
    parser.add_argument("--report-only", action="store_true", help="only read DIR/<variant>/ and report")
    parser.add_argument("--variants", nargs="+", default=list(VARIANTS), choices=list(VARIANTS))
    args = parser.parse_args(argv)
    out = args.out or ROOT / "out" / f"sequence_{args.arm}"
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"sequence_{args.arm}.yaml"
    path.write_text(scenario(args.arm))
    if args.write_only:
        print(path)
        return 0
    for name in [] if args.report_only else args.variants:
        run_variant(path, out / name, VARIANTS[name])
    print(json.dumps(report(args.arm, out), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
