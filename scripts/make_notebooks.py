"""Write the tutorial notebooks of ``examples/`` and execute them, so that they are committed with
their outputs (the documentation site shows those; ``tests/e2e/test_notebooks.py`` re-executes
them and compares the numbers of the cells tagged ``table``).

    .venv/bin/python scripts/make_notebooks.py              # all five (~2 min)
    .venv/bin/python scripts/make_notebooks.py camera       # one

The cells are below, one list per notebook (the pose and pick-and-place ones in
``task_notebooks.py``): Markdown strings start with ``md:``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"
sys.path.insert(0, str(ROOT / "tests"))
from hardware_notebook import hardware  # noqa: E402
from notebook_kernel import kernel_env, kernel_name  # noqa: E402
from task_notebooks import pick_and_place, pose  # noqa: E402

SETUP = """\
# Drake's deprecation warnings are errors here, as in the test suite
import warnings
from pydrake.common.deprecation import DrakeDeprecationWarning

warnings.simplefilter("error", DrakeDeprecationWarning)"""

ARM = """\
import numpy as np
from pydrake.all import AddMultibodyPlantSceneGraph, DiagramBuilder, Parser

URDF = "three_link_arm.urdf"  # in this notebook's folder: a waist, a shoulder, an elbow
Q0 = [0.3, 0.5, 1.2]  # rad, the start pose


def hand_position(plant, q):
    \"\"\"Where the frame `hand` is (m, world) at joint angles q.\"\"\"
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    return plant.GetFrameByName("hand").CalcPoseInWorld(context).translation()"""

REPLAY = """\
import base64
import gzip
import html

from IPython.display import HTML


def inline_replay(meshcat, height=420):
    \"\"\"The Meshcat recording as a standalone page inside an iframe (gzip + base64, unpacked by
    the browser), so the rendered notebook plays it without a running kernel.\"\"\"
    packed = base64.b64encode(gzip.compress(meshcat.StaticHtml().encode(), 9)).decode()
    page = ("<script>(async()=>{const b=Uint8Array.from(atob('" + packed + "'),c=>c.charCodeAt(0));"
            "const t=await new Response(new Blob([b]).stream().pipeThrough("
            "new DecompressionStream('gzip'))).text();document.open();document.write(t);"
            "document.close();})()</script>")
    return HTML(f'<div><iframe style="width:100%;height:{height}px;border:0" '
                f'srcdoc="{html.escape(page)}"></iframe></div>')"""

YOUR_DIAGRAM = [
    "md:# Your diagram: the interceptor on your own arm\n\n"
    "This tutorial builds a Drake `MultibodyPlant` of an arm the package has never seen (a URDF in "
    "this folder), adds the prescribed-time interceptor with `AddPrescribedTimeInterceptor`, "
    "simulates, and checks the paper's property: the hand reaches the moving object **at** the "
    "prescribed time tf, not before, knowing only the arm's kinematics.",
    SETUP,
    "md:## The plant\n\nAny URDF or SDFormat model whose joints are all actuated. "
    "`time_step=0.0` makes a continuous plant, integrated with error control.",
    ARM + """

builder = DiagramBuilder()
plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
Parser(plant).AddModels(URDF)
plant.Finalize()
hand = plant.GetFrameByName("hand")
x0 = hand_position(plant, Q0)
print("joints:", plant.num_positions(), " hand at", np.round(x0, 3), "m")""",
    "md:## The interceptor\n\nOne segment: intercept an object moving at 0.1 m/s along y at "
    "tf = 1 s, with the TBG shape β = 0.75 and the paper's gains. The builder adds the time base "
    "generator, the target, the task-space kinematics, the sliding surface and the controller, "
    "wires them to the plant and returns their handles.",
    """\
from ptint_drake.controllers.ptsmc.builder import AddPrescribedTimeInterceptor, ControllerGains
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import LinearTarget

tf = 1.0
target = LinearTarget(start=x0 + [0.06, -0.08, -0.05], velocity=[0.0, 0.1, 0.0])
handles = AddPrescribedTimeInterceptor(
    builder, plant, hand, Schedule([Segment(start=0.0, tf=tf, beta=0.75)]), [target],
    ControllerGains())  # the paper's K = 50, Λ = 5, k = 3
print([type(s).__name__ for s in (handles.tbg, handles.targets, handles.kinematics,
                                  handles.surface, handles.controller)])""",
    "md:## Simulate, with a Meshcat recording\n\nThe surface's `e` output is the task error "
    "x − x_r (m); a `VectorLogSink` records it. `MeshcatVisualizer` records the motion; the red "
    "ball is the object.",
    """\
import logging
from pydrake.all import (LogVectorOutput, Meshcat, MeshcatVisualizer, Rgba, RigidTransform,
                         Simulator, Sphere)

logging.getLogger("drake").setLevel(logging.WARNING)  # no "Meshcat listening ..." line

e_log = LogVectorOutput(handles.surface.GetOutputPort("e"), builder, publish_period=0.01)
meshcat = Meshcat()
visualizer = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat)
diagram = builder.Build()

simulator = Simulator(diagram)
simulator.get_mutable_integrator().set_target_accuracy(1e-4)
context = simulator.get_mutable_context()
plant.SetPositions(plant.GetMyMutableContextFromRoot(context), Q0)
visualizer.StartRecording()
simulator.AdvanceTo(1.5 * tf)
visualizer.StopRecording()

meshcat.SetObject("object", Sphere(0.02), Rgba(0.9, 0.1, 0.1, 1.0))
recording = visualizer.get_mutable_recording()
for t in np.arange(0.0, 1.5 * tf + 1e-9, 1 / 32):
    recording.SetTransform(recording.frame(t), "object",
                           RigidTransform(target.evaluate(t)[:3]))
visualizer.PublishRecording()""",
    "md:## |e(t)|: the arrival is prescribed\n\nOn the ideal sliding surface |e(tf/2)| is half of "
    "|e(0)| for every β: the arm does not rush; it closes the last millimetres just before tf.",
    """\
log = e_log.FindLog(context)
t, e = log.sample_times(), np.linalg.norm(log.data(), axis=0)
at = lambda s: e[np.searchsorted(t, s)]  # noqa: E731
print(f"|e(0)| = {at(0) * 1e3:.2f} mm, |e(tf/2)| = {at(tf / 2) * 1e3:.2f} mm, "
      f"|e(tf)| = {at(tf) * 1e3:.4f} mm, max |e| after tf = {e[t >= tf].max() * 1e3:.4f} mm")""",
    """\
import matplotlib.pyplot as plt

fig, ax = plt.subplots(figsize=(7, 3.2))
ax.semilogy(t, np.maximum(e, 1e-7) * 1e3)
ax.axvline(tf, color="0.4", ls="--", label="tf (prescribed)")
ax.axhline(1.0, color="r", lw=0.8, label="1 mm")
ax.set_xlabel("t [s]"), ax.set_ylabel("|e| [mm]"), ax.legend()
ax.set_title("the hand's distance to the moving object")
plt.show()""",
    "md:## The replay\n\nThe recording as a standalone page (drag to orbit; the animation controls "
    "are in the panel, top right).",
    REPLAY + "\n\ninline_replay(meshcat)",
    "md:`handles` gives every block, so you can log or re-wire any port; "
    "`connect_actuation=False` leaves the controller's `u` for you, `targets=None` takes the "
    "target from an input port (the next tutorial feeds it from a camera), and `fused=True` puts "
    "the five blocks in one system (the package's fast path).",
]

CAMERA = [
    "md:# A camera in the loop\n\nThe same arm and object, but the controller no longer gets "
    "the object's true motion: a `Camera` samples the position at 30 Hz with 2 mm noise and a "
    "latency, and an estimator (`auto`: an interacting-multiple-model filter that knows only the "
    "samples and the camera's stated noise, rate and latency) gives the interceptor a continuous "
    "estimate of x_r, ẋ_r, ẍ_r. The error is measured against the truth.",
    SETUP,
    ARM,
    "md:## The diagram\n\n`AddCameraEstimators` adds a camera and an estimator per object, "
    "watching the true position (here a `TargetSource` of the object); "
    "`AddPrescribedTimeInterceptor(..., targets=None)` leaves an input port for the estimate.",
    """\
from pydrake.all import LogVectorOutput, Simulator
from ptint_drake.controllers.ptsmc.builder import AddPrescribedTimeInterceptor, ControllerGains
from ptint_drake.systems.perception.camera import MeasurementConfig
from ptint_drake.systems.estimation.kalman import AddCameraEstimators
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import LinearTarget, TargetSource

tf = 1.0


def run(latency, compensate=True, noise=0.002, seed=1):
    \"\"\"Simulate to 1.5 tf; the times, the hand's true error, the estimate's error (m).\"\"\"
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModels(URDF)
    plant.Finalize()
    target = LinearTarget(start=hand_position(plant, Q0) + [0.06, -0.08, -0.05],
                          velocity=[0.0, 0.1, 0.0])
    schedule = Schedule([Segment(start=0.0, tf=tf, beta=0.75)])
    truth = builder.AddSystem(TargetSource(schedule, [target]))
    camera = MeasurementConfig(rate_hz=30.0, noise_std=noise, latency=latency,
                               compensate_latency=compensate, seed=seed)
    estimators = AddCameraEstimators(builder, true_position_ports=[truth.GetOutputPort("x_r")],
                                     schedule=schedule, config=camera, histories=[target])
    handles = AddPrescribedTimeInterceptor(builder, plant, plant.GetFrameByName("hand"),
                                           schedule, None, ControllerGains())
    builder.Connect(estimators.target_port, handles.target_input)
    logs = [LogVectorOutput(port, builder, publish_period=0.01) for port in
            (plant.get_state_output_port(), truth.GetOutputPort("x_r"), estimators.target_port)]
    diagram = builder.Build()
    simulator = Simulator(diagram)
    simulator.get_mutable_integrator().set_target_accuracy(1e-4)
    context = simulator.get_mutable_context()
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context), Q0)
    simulator.AdvanceTo(1.5 * tf)
    state, true_x, estimate = (log.FindLog(context) for log in logs)
    hand = np.array([hand_position(plant, q[:3]) for q in state.data().T])
    return (state.sample_times(), np.linalg.norm(hand - true_x.data().T, axis=1),
            np.linalg.norm(estimate.data()[:3].T - true_x.data().T, axis=1))""",
    "md:## Estimate against truth\n\n33 ms of latency, compensated (the estimator predicts over it).",
    """\
import matplotlib.pyplot as plt

t, e_true, e_estimate = run(latency=0.033)
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.semilogy(t, np.maximum(e_true, 1e-7) * 1e3, label="|hand − object| (true)")
ax.semilogy(t, np.maximum(e_estimate, 1e-7) * 1e3, label="|estimate − object|")
ax.axvline(tf, color="0.4", ls="--", label="tf")
ax.set_xlabel("t [s]"), ax.set_ylabel("mm"), ax.legend(fontsize=8)
plt.show()""",
    "md:## What latency does\n\nThe object moves at 0.1 m/s, so an uncompensated latency L puts "
    "the estimate about 0.1 L behind it (3.3 mm at 33 ms); predicting over the latency removes "
    "that bias and leaves the noise. |e(tf)| and the largest |e| after tf, against the truth:",
    """\
rows = []
for latency in (0.0, 0.033, 0.066):
    for compensate in ((True,) if latency == 0.0 else (True, False)):
        t, e_true, _ = run(latency, compensate)
        k = np.searchsorted(t, tf)
        rows.append((latency * 1e3, compensate, e_true[k] * 1e3, e_true[k:].max() * 1e3))
print("latency [ms] | compensated | |e(tf)| [mm] | hold max [mm]")
for latency, compensate, e_tf, hold in rows:
    print(f"{latency:12.0f} | {str(compensate):11} | {e_tf:12.3f} | {hold:13.3f}")""",
    "md:The scenario file's `measurement` block builds the same thing for the package's runs "
    "(`ptint run conveyor_pair_camera`); `ptint study camera` sweeps noise × latency × estimator.",
    "md:## From pixels to a grasp\n\nWith `measurement.sensor: rgbd` the camera is rendered "
    "(Drake's `RgbdSensor`, D415-style depth noise) and the parts' poses are fitted to its point "
    "clouds. In a pick scenario the fits feed the estimators and the approach and the grasp aim at "
    "the estimate (docs/camera.md). `conveyor_pick_place_rgbd` places its cube at a random yaw and "
    "lateral offset; here its pick diagram runs to 0.6 s: the colour frame with the fitted centre, "
    "and what the approach aims at against the simulated part.",
    """\
import matplotlib.pyplot as plt
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose, project
from ptint_drake.worlds.pick.run import build_pick

scenario = load_scenario("conveyor_pick_place_rgbd")
built = build_pick(scenario)
simulator = Simulator(built.diagram)
context = simulator.get_mutable_context()
built.station.start_running(built.station.plant.GetMyMutableContextFromRoot(context))
simulator.AdvanceTo(0.6)
station = built.diagram.GetSubsystemByName("pick_station")
sc = station.GetMyContextFromRoot(context)
estimator, parts = built.estimates.estimator, built.estimates.parts
fits = estimator.GetOutputPort("fits").Eval(estimator.GetMyContextFromRoot(context))
estimate = parts.GetOutputPort("part_0_pose").Eval(parts.GetMyContextFromRoot(context))
truth = station.GetOutputPort("part_0_pose").Eval(sc)
colour = np.array(station.GetOutputPort("color_image").Eval(sc).data)
camera = scenario.measurement.camera
print("fits (ok, centre mm, yaw deg):",
      [(f.ok, np.round(f.position * 1e3, 1).tolist(), round(float(np.degrees(f.yaw)), 1)) for f in fits])
print("estimate (mm):", np.round(estimate[0:3] * 1e3, 1))
print("simulated part (mm):", np.round(truth[0:3] * 1e3, 1))
uv = project(camera_pose(camera), camera_info(camera), np.array([f.position for f in fits if f.ok]))
plt.imshow(colour[:, :, :3])
plt.plot(uv[:, 0], uv[:, 1], "g+", ms=14, mew=2, label="fitted centre")
plt.legend(), plt.title("colour frame at t = 0.6 s")
plt.show()""",
]

WHICH_CONTROLLER = [
    "md:# Which controller? `compare` and `tune` from Python\n\n"
    "`ptint compare` and `ptint tune` are thin command lines over two functions, "
    "`studies.compare.run_compare` and `studies.tune.run_tune`; here they run from Python on the "
    "paper's curve scenario, on the nominal plant only to keep the notebook short (the command "
    "lines add the ×0.7 and ×1.5 mass variants).",
    SETUP,
    """\
from ptint_drake.simulation.scenario import LoadedScenario
from ptint_drake.studies.compare import run_compare, table_rows

# a bundled name or a YAML file, with --set-style overrides: here the hold after tf shortened
loaded = LoadedScenario.load("curve_b075_tf15", overrides=["duration=2.0"])
result = run_compare(loaded, controllers=["ptsmc", "pd", "smc", "ct_quintic"],
                     variants=["nominal"], workers=2)
print("controller | e(tf) [mm] | t_arrive [s] | verdict")
for row in table_rows(result):
    arrive = "never" if row["t_arrive"] is None else f"{row['t_arrive']:.2f}"
    print(f"{row['controller']:10} | {row['e_tf_norm'] * 1e3:10.4g} | {arrive:>12} | "
          f"{'ok' if row['ok'] else row['reasons']}")""",
    "md:Only the paper's controller (`ptsmc`) and the model-based reference `ct_quintic` (which "
    "is given the model and the target's future) arrive within 1 mm at tf = 1.5 s; `pd` lags the "
    "moving object, `smc` arrives early. The figure `ptint compare` writes:",
    """\
import tempfile
from pathlib import Path
from IPython.display import Image
from ptint_drake.studies.compare import figure

out = Path(tempfile.mkdtemp())
figure(result, out)
Image(filename=str(out / "compare.png"), width=520)""",
    "md:## Tuning K\n\nThe smallest K for which every segment meets the criteria with margin 2 "
    "(e(tf) ≤ 0.5 mm, hold ≤ 1.5 mm) and the actuators saturate at most 5 % of the time: a "
    "log-spaced grid, then bisection. A coarse search here (3 points in [1, 50], one bisection); "
    "the command line's defaults search finer.",
    """\
from ptint_drake.studies.tune import TuneSettings, run_tune

settings = TuneSettings(variants=("nominal",), grid_points=3, bracket=(1.0, 50.0), max_bisections=1)
tuned = run_tune(loaded, settings, workers=2, say=lambda message: None)
print("tried K =", ", ".join(f"{row['gains']['K']:.3g}" for row in tuned["tried"]))
print(f"smallest working K = {tuned['gains']['K']:.3g} (paper: {tuned['paper_value']:g}), "
      f"{tuned['runs']} runs")""",
    """\
from ptint_drake.studies.tune import figure as tune_figure

tune_figure(tuned, out)
Image(filename=str(out / "tune.png"), width=520)""",
]

NOTEBOOKS = {"your_diagram": YOUR_DIAGRAM, "camera": CAMERA, "which_controller": WHICH_CONTROLLER,
             "pose": pose(SETUP), "pick_and_place": pick_and_place(SETUP), "hardware": hardware(SETUP)}
# the cells whose printed numbers the test compares with the committed outputs
TABLE_MARKERS = ('print(f"|e(0)|', "rows = []", 'print("controller', "tried K",
                 'print("         | distance', 'print("t_grasp [s]',
                 'print(f"verdict {metrics')


def notebook(cells: list) -> nbformat.NotebookNode:
    """The notebook of ``cells`` (``md:`` Markdown, else code; print cells tagged ``table``)."""
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    for cell in cells:
        if cell.startswith("md:"):
            nb.cells.append(nbformat.v4.new_markdown_cell(cell[3:]))
            continue
        code = nbformat.v4.new_code_cell(cell)
        if any(m in cell for m in TABLE_MARKERS):
            code.metadata["tags"] = ["table"]
        nb.cells.append(code)
    return nb


def execute(nb: nbformat.NotebookNode, timeout: int = 300) -> nbformat.NotebookNode:
    """Run ``nb`` top to bottom in ``examples/`` (the kernel of ``notebook_kernel``)."""
    NotebookClient(nb, timeout=timeout, kernel_name=kernel_name(),
                   resources={"metadata": {"path": str(EXAMPLES)}}).execute(env=kernel_env())
    return nb


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"of {', '.join(NOTEBOOKS)} (default: all)")
    args = parser.parse_args()
    for name in args.names or NOTEBOOKS:
        t0 = time.perf_counter()
        nb = execute(notebook(NOTEBOOKS[name]))
        nbformat.write(nb, EXAMPLES / f"{name}.ipynb")
        print(f"examples/{name}.ipynb: executed in {time.perf_counter() - t0:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
