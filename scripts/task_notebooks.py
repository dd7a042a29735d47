"""The cells of the two task tutorials of ``examples/`` (a pose, not a point; pick and place), in
the format of ``scripts/make_notebooks.py`` (Markdown strings start with ``md:``), which writes
and executes them.
"""

from __future__ import annotations


def pose(setup: str) -> list:
    """The cells of ``examples/pose.ipynb``; ``setup`` is the shared first code cell."""
    return [
        "md:# A pose, not a point\n\nThe paper intercepts the gripper's *point*. Here the bundled "
        "scenario `curve_pose` asks for the object's frame too: the paper's curve (β = 0.75, "
        "tf = 1.5 s) with an object that tumbles at 36 °/s, caught by a 6-joint arm whose tool frame "
        "must be on the object **and** turned like it at tf.",
        setup,
        "md:`controller.task` chooses what the sliding surface drives to zero: `position` (the "
        "paper's 3-D law, the default), `pose` (6 rows: the position error stacked with c·e_R, the "
        "rotation error as an axis-angle vector; ≥ 6 joints) or `top_down` (approach axis straight "
        "down, fingers across the part; ≥ 5 joints). `rot_scale` c (m per rad, default 0.1: a radian "
        "weighs like 10 cm) weights orientation against position where J⁺ is not an inverse and in "
        "the boundary layer. The same TBG, surface and τ = −K J⁺ s_x; still model-free.",
        """\
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.simulation import simulate

scenario = load_scenario("curve_pose")  # a bundled name or a YAML file
print("task:", scenario.controller.task, " rot_scale:", scenario.controller.rot_scale,
      " model:", scenario.robot.model)
result = simulate(scenario)  # 3 s simulated
segment = result.metrics["segments"][0]
print("status:", result.metrics["status"])""",
        "md:## Distance and angle at tf/2 and tf\n\nOn the ideal surface the angle follows the same "
        "decay law as the distance, about a fixed axis: a little over half of each is left at tf/2 "
        "(the ideal surface leaves exactly half, for every β), nothing at tf.",
        """\
print("         | distance [mm] | angle [deg]")
print(f"at 0     | {segment['e0_norm'] * 1e3:13.3f} | {segment['e_rot0_deg']:11.3f}")
print(f"at tf/2  | {segment['e_half_norm'] * 1e3:13.3f} | {segment['e_rot_half_deg']:11.3f}")
print(f"at tf    | {segment['e_tf_norm'] * 1e3:13.4f} | {segment['e_rot_tf_deg']:11.4f}")""",
        """\
import matplotlib.pyplot as plt
import numpy as np

series, tf = result.series, segment["tf"]
t = series["t"]
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.semilogy(t, np.maximum(np.linalg.norm(series["e_true"], axis=1), 1e-7) * 1e3, label="|e| [mm]")
ax.semilogy(t, np.maximum(series["rot_angle_deg"][:, 0], 1e-5), label="angle [deg]")
ax.axvline(tf, color="0.4", ls="--", label="tf (prescribed)")
ax.set_xlabel("t [s]"), ax.legend(fontsize=8)
ax.set_title("the tool frame's distance and angle to the object frame")
plt.show()""",
        "md:`ptint run curve_pose` does the same from the command line and writes `angle.png`; "
        "see the *Intercepting a pose* page for the orientation targets and the criteria.",
    ]


def pick_and_place(setup: str) -> list:
    """The cells of ``examples/pick_and_place.ipynb``; ``setup`` is the shared first code cell."""
    return [
        "md:# Pick and place\n\nThe paper's assembly task in full: a two-finger gripper on the "
        "5-joint RV-M1, a belt that carries a free box by friction, a tray, contact and a discrete "
        "1 ms plant. The bundled scenario `conveyor_pick_place` picks one part off its belt and "
        "places it in the tray's slot.",
        setup,
        "md:Each task (one part to one slot) becomes six prescribed-time segments: **approach** "
        "(40 mm above the part, from above: `task: top_down`), **descend** (the fingers close so "
        "that they meet the part at tf), **lift**, **carry** (above the slot, turned to its yaw), "
        "**place** (the fingers open at tf) and **retreat**. The target is the part's *simulated* "
        "pose as it rides the belt, not the belt's formula, so a belt that runs fast is a real "
        "disturbance; the payload is unknown to the controller.",
        """\
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.simulation import simulate

result = simulate(load_scenario("conveyor_pick_place"))  # 5 s simulated
for segment in result.metrics["segments"]:
    print(f"{segment['phase']:8} from {segment['start']:.2f} s, tf = {segment['tf']:.2f} s")""",
        "md:## The pick\n\n`t_grasp` is the first time both finger pads touch the part; the "
        "prescribed one is the descend segment's start + tf. The place error is the part's pose "
        "against its slot's at the end of the run; the slip is its largest motion relative to the "
        "tool while carried.",
        """\
pick = result.metrics["picks"][0]
print("t_grasp [s] | prescribed [s] | placed | place error [mm, deg] | slip [mm]")
print(f"{pick['t_grasp']:11.3f} | {pick['t_grasp_prescribed']:14.3f} | "
      f"{'yes' if pick['placed'] else 'no':6} | {pick['place_error_mm']:11.2f}, "
      f"{pick['place_error_deg']:.2f} | {pick['slip_mm']:9.2f}")""",
        "md:The figure `ptint run` writes (`picks.png`): the tool's distance and angle to the part, "
        "the finger opening, the grip force and the part's height; dashed, the prescribed grasp "
        "time; dotted, the close command.",
        """\
import tempfile
from pathlib import Path
from IPython.display import Image
from ptint_drake.worlds.pick.views import pick_figure

path = pick_figure(result.series, result.metrics, Path(tempfile.mkdtemp()) / "picks.png")
Image(filename=str(path), width=900)""",
    ]
