"""Standalone HTML replays of a run: a Meshcat recording saved with ``StaticHtml()``.

The simulation runs without any visualizer (no publish period caps its steps).
Afterwards the logged joint trajectory is replayed at a fixed frame rate into a
separate diagram (plant + SceneGraph + MeshcatVisualizer), while the moving
objects, the target's path, the gripper's trail and the interception markers
are animated with ``Meshcat.SetTransform(..., time_in_recording=t)``.

Objects: one sphere per segment target, slightly larger than the end
effector's own sphere so that a caught object stays visible around the tool
instead of disappearing inside it.  Until its segment's prescribed time an
object follows its own path (rides its conveyor); from then on it is held: it
moves with the gripper point for the rest of the run (the arm carries it).

The floor is a light plate at z = 0 with a 10 cm grid under the working area
(meshcat's own grid is hidden: in a recorded page it is drawn edge-on).

Every replay page (``finish_page``, also the pick world's) loops its recording and carries an
overlay: the run's name, the replay's time (``t = … s``, read from the animation each frame), a
pause / play button and a legend of what each colour is (the page's code: ``replay_page``).

A task with orientation (``controller.task`` pose or top_down, issue 19) adds two frame
triads (x red, y green, z blue): a thin one on the gripper's tool frame (``triads/gripper``,
forward kinematics of the replayed q) and a thicker, translucent one on the active object
(``triads/object``) in the orientation the task asks the tool to take there — the object's
own frame (``pose``) or its top-down grasp Rz(ψ)·Rx(π) on the branch nearest the tool's yaw
(``top_down``).  At an interception the thin triad sits inside the thick one.
"""

from __future__ import annotations

import logging

import numpy as np
from pydrake.geometry import (Box, Cylinder, Meshcat, MeshcatParams, MeshcatVisualizer,
                              MeshcatVisualizerParams, Rgba, Role, Sphere)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.systems.task.error import task_reference
from ptint_drake.views.replay_page import (  # noqa: F401
    CAMERA,
    LOOP_REPETITIONS,
    OVERLAY_ID,
    TIME_ID,
    css_color,  # (re-exported)
    finish_page,
    overlay_html,
    with_camera,
)

_MESHCAT = None
COLORS = (Rgba(0.85, 0.15, 0.15, 1), Rgba(0.15, 0.55, 0.9, 1), Rgba(0.2, 0.7, 0.25, 1),
          Rgba(0.8, 0.6, 0.1, 1), Rgba(0.6, 0.3, 0.8, 1))


def shared_meshcat() -> Meshcat:
    """One Meshcat per process (each holds a port until the process exits)."""
    global _MESHCAT
    if _MESHCAT is None:
        logger = logging.getLogger("drake")
        level = logger.level
        logger.setLevel(logging.WARNING)  # not "listening at http://..." (replays are files)
        try:
            _MESHCAT = Meshcat(MeshcatParams(host="localhost"))
        finally:
            logger.setLevel(level)
    return _MESHCAT


OBJECT_RADIUS = 0.018   # m, when the end effector has no geometry to compare with
FLOOR_COLOR = Rgba(0.93, 0.93, 0.9, 1.0)
FLOOR_LINES = Rgba(0.55, 0.55, 0.55, 1.0)


def end_effector_radius(plant, scene_graph, context, frame_name) -> float:
    """The radius of the largest illustration shape on the end effector's body (0 if none)."""
    if not frame_name or not plant.HasFrameNamed(frame_name):
        return 0.0
    body = plant.GetFrameByName(frame_name).body()
    inspector = scene_graph.model_inspector()
    frame_id = plant.GetBodyFrameIdIfExists(body.index())
    if frame_id is None:
        return 0.0
    radius = 0.0
    for gid in inspector.GetGeometries(frame_id, Role.kIllustration):
        shape = inspector.GetShape(gid)
        if isinstance(shape, Sphere):
            radius = max(radius, shape.radius())
        elif isinstance(shape, Cylinder):
            radius = max(radius, shape.radius(), 0.5 * shape.length())
        elif isinstance(shape, Box):
            radius = max(radius, 0.5 * max(shape.width(), shape.depth(), shape.height()))
    return radius


def object_radius(tool_radius: float) -> float:
    """Objects are drawn 20 % larger than the tool's sphere: a caught object encloses it."""
    return max(OBJECT_RADIUS, 1.2 * tool_radius)


def floor_extent(points: np.ndarray, margin: float = 0.15, step: float = 0.1):
    """(x_min, x_max, y_min, y_max) on the ``step`` grid, covering the robot's base,
    ``points`` (N × 3) and ``margin``."""
    pts = np.vstack([np.zeros((1, 3)), points.reshape(-1, 3)])
    lo = np.floor((pts[:, :2].min(axis=0) - margin) / step) * step
    hi = np.ceil((pts[:, :2].max(axis=0) + margin) / step) * step
    return lo[0], hi[0], lo[1], hi[1]


def draw_floor(meshcat: Meshcat, extent, step: float = 0.1) -> None:
    """A floor plate over ``extent`` (x0, x1, y0, y1, m) just below z = 0 with grid lines every
    ``step`` m, in place of Meshcat's own grid and axes (both hidden)."""
    x0, x1, y0, y1 = extent
    meshcat.SetProperty("/Grid", "visible", False)
    meshcat.SetProperty("/Axes", "visible", False)  # the world axes at the base: not in the legend
    meshcat.SetObject("floor/plate", Box(x1 - x0, y1 - y0, 0.004), FLOOR_COLOR)
    meshcat.SetTransform("floor/plate", RigidTransform([0.5 * (x0 + x1), 0.5 * (y0 + y1), -0.0025]))
    xs = np.arange(x0, x1 + 0.5 * step, step)
    ys = np.arange(y0, y1 + 0.5 * step, step)
    z = 0.0005
    starts = np.hstack([np.array([xs, np.full_like(xs, y0), np.full_like(xs, z)]),
                        np.array([np.full_like(ys, x0), ys, np.full_like(ys, z)])])
    ends = np.hstack([np.array([xs, np.full_like(xs, y1), np.full_like(xs, z)]),
                      np.array([np.full_like(ys, x1), ys, np.full_like(ys, z)])])
    meshcat.SetLineSegments("floor/grid", starts, ends, 1.0, FLOOR_LINES)


def interception_legend(n_objects: int, ends, belts: bool, triads: bool) -> list:
    """The legend of an interception replay: each object's colour, the markers, the trail."""
    legend = [(css_color(COLORS[i % len(COLORS)]),
               f"object {i}: the target of segment {i}, caught at its prescribed time {end:g} s "
               "(a faint line of its colour: its path)") for i, end in enumerate(ends[:n_objects])]
    legend += [("rgba(255, 230, 0, 1)", "yellow marker: where the gripper is at the prescribed time "
                "(shown from then on)"),
               ("rgba(26, 26, 26, 0.9)", "black line: the gripper's trail")]
    if belts:
        legend.append(("rgba(77, 77, 77, 1)", "grey boxes: the conveyor belts"))
    if triads:
        legend.append(("rgba(255, 0, 0, 0.45)", "axes (x red, y green, z blue): thin, the tool frame; "
                       "thick and faint, the orientation the task asks for at the object"))
    legend.append((css_color(FLOOR_COLOR), "floor, 10 cm grid"))
    return legend


def held_object_index(t: float, starts, ends) -> int:
    """Index of the object the gripper holds at time t (-1 if none).

    Object i is caught at its segment's prescribed time ``ends[i]`` and held until
    the next segment starts (then it is put down where it is); the last object is
    held to the end of the run.
    """
    for i, end in enumerate(ends):
        release = starts[i + 1] if i + 1 < len(starts) else np.inf
        if end <= t < release:
            return i
    return -1


def object_positions(series: dict, starts, ends) -> np.ndarray:
    """(N, n_objects, 3): each object on its own path until caught, then with the gripper.

    An object caught earlier and released when the next segment starts stays where
    it was released (the arm put it down), which is what the assembly task shows.
    """
    t = series["t"]
    objs = series["objects"].reshape(len(t), -1, 3).copy()
    x = series["x"]
    n = objs.shape[1]
    held = np.array([held_object_index(tk, starts, ends) for tk in t])
    for i in range(n):
        release = starts[i + 1] if i + 1 < n else np.inf
        carried = held == i
        objs[carried, i, :] = x[carried]
        after = t >= release
        if after.any() and carried.any():
            objs[after, i, :] = x[np.nonzero(carried)[0][-1]]
    return objs


# (length m, radius m, opacity) of the gripper's and the object's triads
TRIADS = {"gripper": (0.045, 0.002, 1.0), "object": (0.06, 0.004, 0.45)}
TRIAD_AXES = (("x", (1.0, 0.0, 0.0), RotationMatrix.MakeYRotation(np.pi / 2)),
              ("y", (0.0, 1.0, 0.0), RotationMatrix.MakeXRotation(-np.pi / 2)),
              ("z", (0.0, 0.0, 1.0), RotationMatrix()))


def draw_triad(meshcat: Meshcat, path: str, length: float, radius: float, alpha: float) -> None:
    """Three cylinders under ``path`` along its frame's x (red), y (green) and z (blue) axes from
    its origin (``path`` itself is placed by its caller)."""
    for axis, rgb, R in TRIAD_AXES:
        meshcat.SetObject(f"{path}/{axis}", Cylinder(radius, length), Rgba(*rgb, alpha))
        meshcat.SetTransform(f"{path}/{axis}", RigidTransform(R, 0.5 * length * np.asarray(rgb)))


def draw_triads(meshcat: Meshcat) -> None:
    """``triads/gripper`` and ``triads/object`` (``draw_triad``; placed per frame by ``_record``)."""
    for name, (length, radius, alpha) in TRIADS.items():
        draw_triad(meshcat, f"triads/{name}", length, radius, alpha)


def outline_segments(shape: str, size, sides: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """(starts, ends), each 3 × M: the edges of a box (``size`` [x, y, z]) or of a vertical
    cylinder (``size`` [diameter, height]: its two rims as ``sides``-gons and four sides) centred
    at the origin of its frame, for ``Meshcat.SetLineSegments``."""
    if shape == "box":
        half = 0.5 * np.asarray(size, float)
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
        pairs = [(a, b) for a in range(8) for b in range(a + 1, 8)
                 if np.count_nonzero(corners[a] != corners[b]) == 1]
        return corners[[a for a, _ in pairs]].T.copy(), corners[[b for _, b in pairs]].T.copy()
    radius, half = 0.5 * float(size[0]), 0.5 * float(size[1])
    angles = np.linspace(0.0, 2.0 * np.pi, sides + 1)
    rim = np.array([radius * np.cos(angles), radius * np.sin(angles)])
    starts, ends = [], []
    for z in (-half, half):
        starts.append(np.vstack([rim[:, :-1], np.full(sides, z)]))
        ends.append(np.vstack([rim[:, 1:], np.full(sides, z)]))
    quarter = rim[:, 0:sides:max(sides // 4, 1)]
    starts.append(np.vstack([quarter, np.full(quarter.shape[1], -half)]))
    ends.append(np.vstack([quarter, np.full(quarter.shape[1], half)]))
    return np.hstack(starts), np.hstack(ends)


def _triad_poses(tool_pose: RigidTransform, orientation, k: int, active: int, p_obj) -> tuple:
    """(gripper, object) poses of the triads: the tool frame, and at the active object's drawn
    position ``p_obj`` the orientation its task asks for (``orientation`` = (task, rotations:
    N × objects × 9, each object's true R_r row-major at the logged times), sample k)."""
    task, rotations = orientation
    rot_r = list(rotations[k, active]) + [0.0] * 6  # ω_r, ω̇_r: not drawn
    R_tool = tool_pose.rotation().matrix()
    R_task = np.reshape(task_reference(task, rot_r, R_tool)[0:9], (3, 3))
    return tool_pose, RigidTransform(RotationMatrix(R_task), p_obj)


def _record(meshcat, viz, plant, context, series: dict, objs: np.ndarray, ends, fps: float,
            triads=None) -> None:
    """The animation: the robot from the logged q, the objects, the intercept markers, and with
    ``triads`` = (tool frame, starts, orientation) the frame triads (``_triad_poses``)."""
    t = series["t"]
    n_obj = objs.shape[1]
    plant_context = plant.GetMyMutableContextFromRoot(context)
    meshcat.StartRecording(frames_per_second=fps, set_visualizations_while_recording=False)
    frames = np.arange(t[0], t[-1] + 0.5 / fps, 1.0 / fps)
    nq = plant.num_positions()
    for tf_ in frames:
        q = np.array([np.interp(tf_, t, series["q"][:, j]) for j in range(nq)])
        plant.SetPositions(plant_context, q)
        context.SetTime(tf_)
        viz.ForcedPublish(viz.GetMyContextFromRoot(context))
        for i in range(n_obj):
            p = np.array([np.interp(tf_, t, objs[:, i, k]) for k in range(3)])
            meshcat.SetTransform(f"objects/object_{i}", RigidTransform(p), time_in_recording=tf_)
            meshcat.SetProperty(f"intercepts/point_{i}", "visible", bool(tf_ >= ends[i]),
                                time_in_recording=tf_)
        if triads is not None:
            frame, starts, orientation = triads
            active = max(int(np.searchsorted(starts, tf_, side="right")) - 1, 0)
            p_obj = np.array([np.interp(tf_, t, objs[:, active, k]) for k in range(3)])
            k = min(int(np.searchsorted(t, tf_)), len(t) - 1)
            poses = _triad_poses(frame.CalcPoseInWorld(plant_context), orientation, k, active, p_obj)
            for name, pose in zip(TRIADS, poses):
                meshcat.SetTransform(f"triads/{name}", pose, time_in_recording=tf_)


def replay_visualizer(builder: DiagramBuilder, scene_graph) -> tuple:
    """The shared Meshcat cleared (its scene and its recording) and an illustration visualizer of
    ``scene_graph`` added to ``builder``, which is then built: (visualizer, meshcat, the diagram's
    default context) for a world's replay to record into."""
    meshcat = shared_meshcat()
    meshcat.Delete()
    meshcat.DeleteRecording()
    viz = MeshcatVisualizer.AddToBuilder(
        builder, scene_graph, meshcat, MeshcatVisualizerParams(role=Role.kIllustration))
    return viz, meshcat, builder.Build().CreateDefaultContext()


def _replay_diagram(model_file: str):
    """The model in a plant + SceneGraph + MeshcatVisualizer diagram (no dynamics: the logged
    q is replayed into it); returns (plant, scene_graph, visualizer, meshcat, root context)."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    Parser(plant).AddModels(str(model_file))
    plant.Finalize()
    viz, meshcat, context = replay_visualizer(builder, scene_graph)
    return plant, scene_graph, viz, meshcat, context


def _draw_scene(meshcat: Meshcat, series: dict, raw: np.ndarray, ends, radius: float, belts) -> None:
    """What does not move with the arm: the floor, each target's path, the objects and
    interception markers (placed later by ``_record``), the gripper's trail, the belts."""
    t = series["t"]
    draw_floor(meshcat, floor_extent(np.vstack([series["x"], raw.reshape(-1, 3)]
                                               + [np.vstack(b) for b in belts])))
    for i in range(raw.shape[1]):
        color = COLORS[i % len(COLORS)]
        meshcat.SetLine(f"paths/target_{i}", raw[:, i, :].T.copy(), 2.0,
                        Rgba(color.r(), color.g(), color.b(), 0.6))
        meshcat.SetObject(f"objects/object_{i}", Sphere(radius), color)
        meshcat.SetObject(f"intercepts/point_{i}", Sphere(0.01), Rgba(1, 0.9, 0, 1))
        k = min(np.searchsorted(t, ends[i]), len(t) - 1)
        meshcat.SetTransform(f"intercepts/point_{i}", RigidTransform(series["x"][k]))
    meshcat.SetLine("paths/gripper_trail", series["x"].T.copy(), 3.0, Rgba(0.1, 0.1, 0.1, 0.9))
    for j, (a, b) in enumerate(belts):  # a belt under each object, as wide as the object
        length = float(np.linalg.norm(b - a))
        meshcat.SetObject(f"conveyors/belt_{j}", Box(2.4 * radius, length, 0.01),
                          Rgba(0.3, 0.3, 0.3, 1))
        meshcat.SetTransform(f"conveyors/belt_{j}",
                             RigidTransform(0.5 * (a + b) - [0, 0, radius + 0.005]))


def write_replay(series: dict, metrics: dict, model_file: str, path, fps: float = 30.0,
                 conveyors=None, end_effector: str | None = None, orientation=None,
                 title: str = "") -> int:
    """Write a standalone replay HTML to ``path``; returns its size in bytes.

    ``conveyors``: optional list of (start_xyz, end_xyz) belts to draw as boxes.
    ``end_effector``: the frame whose body's size sets the objects' size (see module doc).
    ``orientation``: (task, rotations) of a task with orientation — rotations (N × objects × 9)
    each object's true R_r (row-major) at ``series["t"]`` — to draw the frame triads on
    ``end_effector`` and the active object.  ``title``: the overlay's first line (``finish_page``).
    """
    plant, scene_graph, viz, meshcat, context = _replay_diagram(model_file)
    starts = [s["start"] for s in metrics["segments"]]
    ends = [s["start"] + s["tf"] for s in metrics["segments"]]
    objs = object_positions(series, starts, ends)
    raw = series["objects"].reshape(len(series["t"]), -1, 3)
    radius = object_radius(end_effector_radius(plant, scene_graph, context, end_effector))
    belts = [(np.asarray(a, float), np.asarray(b, float)) for a, b in (conveyors or [])]
    _draw_scene(meshcat, series, raw, ends, radius, belts)
    triads = None
    if orientation is not None:
        draw_triads(meshcat)
        triads = (plant.GetFrameByName(end_effector), starts, orientation)
    _record(meshcat, viz, plant, context, series, objs, ends, fps, triads)
    legend = interception_legend(objs.shape[1], ends, bool(belts), triads is not None)
    html = finish_page(meshcat, title or "replay", legend)
    with open(path, "w", encoding="utf-8") as f:
        f.write(html)
    meshcat.DeleteRecording()
    return len(html)
