"""What ``ptint run`` draws for a pick and place: a figure of the picks and a replay of the world.

``pick_figure`` — ``picks.png``: per pick (a row), over the task's time: the tool's distance to
the part (mm, log scale) and its angle from the top-down grasp (deg), the finger opening (mm) with
the grasp state the gripper reported (``systems.gripper.GraspObserver``: open … lost, a step line),
the grip force (N): the measured contact force squeezing the part (the smaller of the two pads'
normal forces, as ``peak_grip_force_N``) with the drives' force thin beside it, and the part's
height (mm); each attempt's prescribed grasp time (dashed) and close command (dotted) marked.

``estimate_figure`` — ``estimates.png``, for a run with an RGB-D camera: per pick (a row), the
part's estimate (what the pick aimed at) minus the truth (the simulated part) over time — along
its belt and across it (mm) and in yaw (deg, folded by the part's symmetry) — with each fit the
estimators were given (dots, at the frame's time: the fit minus the truth then), the frames'
times (grey ticks) and the prescribed grasp time (dashed) marked; up to 0.3 s past the grasp
(after it the part is in the hand); the vertical range is that from the first fit to the grasp
(the nominal place drawn before the first fit may leave the axes).

``write_pick_replay`` — ``replay.html``: the whole plant (arm, fingers, belts, parts, tray) rebuilt
from the scenario and replayed from its logged [q; v] at 30 frames per second into a Meshcat
recording, saved standalone with ``StaticHtml()`` (``replay``).  With an RGB-D camera it also shows
what the perception had (issue 34): the point cloud of each pick's first fit (magenta) and of its
grasp (violet) — the frame re-rendered, cropped and downsampled as the perception did
(``camera_frames.camera_views``) — from the frame's time until the pick's next cloud's frame (the
grasp's: ``GRASP_TAIL``; ``cloud_intervals``), and per part its
estimate (series ``part_estimate_k``, what the approach and the grasp aimed at) as a yellow outline
of its known shape with a frame triad, beside the simulated part, until ``GRASP_TAIL`` past its
pick's prescribed grasp (the part is in the hand then; the estimate runs on along the belt).
The floor is drawn under the whole scene (``draw_pick_floor``), Meshcat's grid and axes hidden, and
the page loops with the time, a pause / play button and a legend (``replay.finish_page``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def pick_figure(series: dict, metrics: dict, path: Path) -> Path:
    """Draw ``picks.png`` (module docstring) from a pick run's series and metrics."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    from ptint_drake.worlds.pick.metrics import rotation_of  # noqa: PLC0415
    from ptint_drake.worlds.pick.probe import PART_WIDTH  # noqa: PLC0415

    t, probe = series["t"], series["probe"]
    picks = metrics["picks"]
    fig, axes = plt.subplots(len(picks), 4, figsize=(14, 3.0 * len(picks)), squeeze=False)
    for row, pick in enumerate(picks):
        k = pick["part_index"]
        block = probe[:, PART_WIDTH * k: PART_WIDTH * (k + 1)]
        distance = 1e3 * np.linalg.norm(block[:, 0:3] - probe[:, -7:-4], axis=1)
        angle = np.array([np.degrees(np.arccos(np.clip(
            (rotation_of(probe[j, -4:]) @ [1.0, 0.0, 0.0]) @ (rotation_of(block[j, 3:7]) @ [1.0, 0.0, 0.0]),
            -1.0, 1.0))) for j in range(len(t))])
        angle = np.minimum(angle, 180.0 - angle)  # the fingers' axis: a half turn is the same grasp
        opening = 1e3 * (series["gripper_state"][:, 0] + series["gripper_state"][:, 1])
        contact = np.min(series["grip_forces"][:, 2 * k: 2 * k + 2], axis=1)  # what squeezes the part
        drive = -np.mean(series["grip_force"], axis=1)
        panels = [(distance, "tool to part (mm)", True), (opening, "finger opening, grasp state", False),
                  (contact, "contact grip force (N)", False), (1e3 * block[:, 2], "part height (mm)", False)]
        for i, (ax, (values, label, log)) in enumerate(zip(axes[row], panels)):
            ax.plot(t, np.maximum(values, 1e-3) if log else values, lw=1.2)
            if log:
                ax.set_yscale("log")
                twin = ax.twinx()
                twin.plot(t, angle, color="tab:orange", lw=0.8)
                twin.set_ylabel("angle (deg)", color="tab:orange")
            if i == 1 and "grasp_state" in series:
                _state_line(ax.twinx(), t, series["grasp_state"])
                ax.set_ylabel("opening (mm)")
            if i == 2:
                ax.plot(t, drive, color="0.6", lw=0.7, label="drives' force")
                ax.legend(fontsize=7, loc="upper right")
            for attempt in pick.get("attempt_details") or [pick]:  # each attempt's close and grasp
                ax.axvline(attempt["t_grasp_prescribed"], color="k", ls="--", lw=0.8)
                ax.axvline(attempt["t_close_command"], color="tab:red", ls=":", lw=0.8)
            ax.set_title(f"pick {row} ({pick['part']}): {label}", fontsize=9)
            ax.set_xlabel("t (s)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


GRASP_TAIL = 0.3  # s, drawn past a pick's prescribed grasp in estimates.png


def _yaw(block: np.ndarray) -> np.ndarray:
    """The yaw of the row-major rotations in columns 3:12 of [x (3), R (9)] rows."""
    return np.arctan2(block[:, 6], block[:, 3])


def estimate_figure(series: dict, metrics: dict, directions: list, symmetries: list, path: Path) -> Path:
    """Draw ``estimates.png`` (module docstring); ``directions``: per part its belt's unit
    direction, ``symmetries``: per part its yaw symmetry (rad; 0: none known, ``part_fit.yaw_symmetry``)."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    from ptint_drake.systems.perception.part_fit import fold_yaw  # noqa: PLC0415

    t, picks = np.asarray(series["t"]), metrics["picks"]
    fig, axes = plt.subplots(len(picks), 3, figsize=(13, 2.8 * len(picks)), squeeze=False)
    for row, pick in enumerate(picks):
        k = pick["part_index"]
        true, estimate, fit = (np.asarray(series[f"{name}_{k}"])
                               for name in ("part_true", "part_estimate", "fit"))
        u = np.asarray(directions[k], float)
        across = np.array([-u[1], u[0], 0.0])
        keep = t <= pick["t_grasp_prescribed"] + GRASP_TAIL
        error = estimate[:, 0:3] - true[:, 0:3]
        stamps, first = np.unique(fit[:, 0], return_index=True)
        valid = fit[first, 4] > 0.5
        stamps, first = stamps[valid], first[valid]
        at = np.searchsorted(t, stamps).clip(0, len(t) - 1)  # the truth at each frame's time
        fit_error = fit[first, 1:4] - true[at, 0:3]
        fit_yaw = np.arctan2(fit[first, 8], fit[first, 5])  # R[1, 0], R[0, 0] after [stamp, x, y, z, valid]
        dyaw, fit_dyaw = _yaw(estimate) - _yaw(true), fit_yaw - _yaw(true[at])
        # (a part of any yaw, symmetry 0: fold_yaw's 0 for each)
        yaw_error = np.degrees(fold_yaw(dyaw, symmetries[k]) + 0.0 * dyaw)
        fit_yaw_error = np.degrees(fold_yaw(fit_dyaw, symmetries[k]) + 0.0 * fit_dyaw)
        panels = (("along the belt (mm)", 1e3 * error @ u, 1e3 * fit_error @ u),
                  ("across the belt (mm)", 1e3 * error @ across, 1e3 * fit_error @ across),
                  ("yaw (deg)", yaw_error, fit_yaw_error))
        shown = stamps <= pick["t_grasp_prescribed"] + GRASP_TAIL
        # the vertical range: from the first fit on to the grasp (before it, the nominal place)
        seen = keep & (t >= (stamps[0] if len(stamps) else 0.0)) & (t <= pick["t_grasp_prescribed"])
        for ax, (label, values, fits) in zip(axes[row], panels):
            ax.plot(t[keep], values[keep], lw=1.2, label="estimate − truth")
            if np.any(seen):
                lo, hi = np.percentile(np.r_[values[seen], fits[shown]], [1, 99])
                pad = max(0.25 * (hi - lo), 0.2)
                ax.set_ylim(min(lo, 0.0) - pad, max(hi, 0.0) + pad)
            ax.plot(stamps[shown], fits[shown], ".", ms=3, color="tab:orange", label="fit − truth")
            ax.axhline(0.0, color="0.5", lw=0.5)
            for s in stamps[shown]:
                ax.axvline(s, ymin=0.0, ymax=0.04, color="0.5", lw=0.6)
            ax.axvline(pick["t_grasp_prescribed"], color="k", ls="--", lw=0.8)
            ax.set_title(f"pick {row} ({pick['part']}): estimate error {label}", fontsize=9)
            ax.set_xlabel("t (s)")
        axes[row][0].legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _state_line(ax, t: np.ndarray, codes: np.ndarray) -> None:
    """The gripper's reported grasp state over time, a step line on its own axis (open … lost)."""
    from ptint_drake.systems.gripper import GRASP_STATES  # noqa: PLC0415

    ax.step(t, codes, where="post", color="tab:green", lw=0.8)
    ax.set_yticks(range(len(GRASP_STATES)), GRASP_STATES, fontsize=7, color="tab:green")
    ax.set_ylim(-0.5, len(GRASP_STATES) - 0.5)


def replay_world(scenario):
    """The scenario's whole pick world (arm, gripper, belts, parts, tray) in a plant with a
    MeshcatVisualizer on the shared Meshcat, cleared: (plant, visualizer, Meshcat, root context) —
    no dynamics, a logged plant state is set into it."""
    from pydrake.geometry import MeshcatVisualizer, MeshcatVisualizerParams, Role  # noqa: PLC0415
    from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig  # noqa: PLC0415
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.worlds.pick.run import world_config  # noqa: PLC0415
    from ptint_drake.worlds.pick.station import _add_world  # noqa: PLC0415
    from ptint_drake.replay import shared_meshcat  # noqa: PLC0415

    config = world_config(scenario)
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(time_step=config.time_step), builder)
    _add_world(plant, scene_graph, config)
    plant.Finalize()
    meshcat = shared_meshcat()
    meshcat.Delete()
    meshcat.DeleteRecording()
    viz = MeshcatVisualizer.AddToBuilder(builder, scene_graph, meshcat,
                                         MeshcatVisualizerParams(role=Role.kIllustration))
    return plant, viz, meshcat, builder.Build().CreateDefaultContext()


CLOUD_HOLD = 0.25  # s, the least a frame's cloud stays shown after its frame (one replay frame is 33 ms)
CLOUD_POINT_SIZE = 0.002  # m (the cloud's voxel is 1.5 mm)
CLOUD_RGBA = {"first_fit": (1.0, 0.1, 0.8, 1.0), "grasp": (0.55, 0.25, 1.0, 1.0)}  # magenta, violet
ESTIMATE_RGBA = (1.0, 0.85, 0.0, 1.0)  # yellow: seen on the blue parts and the black belts
ESTIMATE_TRIAD = (0.04, 0.0015, 1.0)  # (length m, radius m, opacity) of the estimate's axes


def draw_camera_clouds(meshcat, scenario, series: dict, metrics: dict) -> list[tuple[str, float]]:
    """Each pick's cloud at its first fit and at its grasp (``camera_frames.camera_views``: the
    frame re-rendered, cropped and downsampled as the perception did) as points under
    ``camera/clouds/pick{i}_{first_fit,grasp}``, hidden until shown by ``show_at``;
    returns [(path, the frame's time)]."""
    from pydrake.geometry import Rgba  # noqa: PLC0415
    from pydrake.perception import PointCloud  # noqa: PLC0415

    from ptint_drake.worlds.pick.camera_frames import camera_views  # noqa: PLC0415

    shown = []
    for view in camera_views(scenario, series, metrics):
        cloud = PointCloud(len(view.points))
        cloud.mutable_xyzs()[:] = view.points.T
        path = f"camera/clouds/{view.label}"
        meshcat.SetObject(path, cloud, CLOUD_POINT_SIZE, Rgba(*CLOUD_RGBA[view.label.split("_", 1)[1]]))
        meshcat.SetProperty(path, "visible", False)
        shown.append((path, view.t))
    return shown


def cloud_intervals(clouds: list) -> list[tuple[str, float, float]]:
    """(path, on, off) of each cloud of ``draw_camera_clouds`` ([(path, frame time)]): shown from
    its frame until the next cloud drawn for the same pick (the first fit's until the grasp's),
    the last of a pick for ``GRASP_TAIL`` (as long as the estimate stays drawn), at least
    ``CLOUD_HOLD``.  The cloud stays where the part was at its frame; the part moves on."""
    out = []
    for path, t in clouds:
        pick = path.rsplit("/", 1)[-1].split("_", 1)[0]
        later = [u for p, u in clouds if p.rsplit("/", 1)[-1].split("_", 1)[0] == pick and u > t]
        off = min(later) if later else t + GRASP_TAIL
        out.append((path, t, max(off, t + CLOUD_HOLD)))
    return out


def pick_legend(scenario, camera: bool) -> list:
    """The legend of a pick replay (``replay.finish_page``)."""
    from ptint_drake.replay import FLOOR_COLOR, css_color  # noqa: PLC0415

    legend = [("rgba(40, 90, 200, 1)", "the parts, on their belts (dark), to the tray"),
              ("rgba(150, 150, 150, 1)", "the arm and its two-finger gripper")]
    if camera:
        rgba = {k: "rgba({}, {}, {}, 1)".format(*(round(255 * c) for c in v[:3]))
                for k, v in CLOUD_RGBA.items()}
        legend += [(rgba["first_fit"], "magenta points: the depth camera's point cloud at the pick's "
                    "first fit (shown until the grasp's frame; it stays where the part was)"),
                   (rgba["grasp"], "violet points: the cloud at the prescribed grasp"),
                   ("rgba(255, 217, 0, 1)", "yellow outline and axes: the part's estimate, what the arm aims "
                    f"at (until {GRASP_TAIL:g} s past the grasp)")]
    legend.append((css_color(FLOOR_COLOR), "floor, 10 cm grid"))
    return legend


def draw_pick_floor(meshcat, plant, context) -> None:
    """The floor (``replay.draw_floor``: the plate, a 10 cm grid, Meshcat's grid hidden) under every
    body of the plant at its posed state, with a margin."""
    from pydrake.multibody.tree import BodyIndex  # noqa: PLC0415

    from ptint_drake.replay import draw_floor, floor_extent  # noqa: PLC0415

    plant_context = plant.GetMyContextFromRoot(context)
    points = np.array([plant.EvalBodyPoseInWorld(plant_context, plant.get_body(BodyIndex(i))).translation()
                       for i in range(1, plant.num_bodies())])
    draw_floor(meshcat, floor_extent(points, margin=0.2))


def draw_estimates(meshcat, scenario) -> None:
    """Per part k, ``estimates/part_{k}``: its known shape's outline (``replay.outline_segments``)
    in blue and a frame triad, posed by ``estimate_poses``."""
    from pydrake.geometry import Rgba  # noqa: PLC0415

    from ptint_drake.replay import draw_triad, outline_segments  # noqa: PLC0415

    for k, part in enumerate(scenario.pick.parts):
        starts, ends = outline_segments(part.shape, part.size)
        meshcat.SetLineSegments(f"estimates/part_{k}/outline", starts, ends, 2.0, Rgba(*ESTIMATE_RGBA))
        draw_triad(meshcat, f"estimates/part_{k}/triad", *ESTIMATE_TRIAD)


def estimate_shown_until(scenario, metrics: dict) -> list[float]:
    """Per part: until when its estimate is drawn — its pick's prescribed grasp + ``GRASP_TAIL``
    (then it is in the hand and the estimate, a prediction along the belt, is no longer aimed at);
    a part with no pick: the whole run."""
    until = [np.inf] * len(scenario.pick.parts)
    for pick in metrics["picks"]:
        until[pick["part_index"]] = float(pick["t_grasp_prescribed"]) + GRASP_TAIL
    return until


def estimate_pose(series: dict, part: int, t: float):
    """The part's estimate (series ``part_estimate_{part}``: [x, R row-major]) at the logged time
    nearest ``t``, as a RigidTransform."""
    from pydrake.math import RigidTransform, RotationMatrix  # noqa: PLC0415

    times = np.asarray(series["t"])
    row = np.asarray(series[f"part_estimate_{part}"])[min(int(np.searchsorted(times, t)), len(times) - 1)]
    return RigidTransform(RotationMatrix.ProjectToRotationMatrix(np.reshape(row[3:12], (3, 3))), row[0:3])


def write_pick_replay(scenario, series: dict, metrics: dict, path: Path, title: str = "") -> int:
    """Write ``replay.html`` (module docstring); returns its size in bytes."""
    from ptint_drake.replay import finish_page  # noqa: PLC0415
    plant, viz, meshcat, context = replay_world(scenario)
    plant_context = plant.GetMyMutableContextFromRoot(context)
    times, states = series["replay_t"], series["plant_state"]
    plant.SetPositions(plant_context, states[0][:plant.num_positions()])
    draw_pick_floor(meshcat, plant, context)
    clouds, until, visible = [], [], {}
    camera = scenario.measurement is not None and scenario.measurement.sensor == "rgbd"
    if camera:
        clouds = cloud_intervals(draw_camera_clouds(meshcat, scenario, series, metrics))
        draw_estimates(meshcat, scenario)
        until = estimate_shown_until(scenario, metrics)
    meshcat.StartRecording(frames_per_second=30.0, set_visualizations_while_recording=False)
    for t, x in zip(times, states):
        plant.SetPositions(plant_context, x[:plant.num_positions()])
        context.SetTime(float(t))
        viz.ForcedPublish(viz.GetMyContextFromRoot(context))
        shown = [(cloud, on - 1e-6 <= t < off) for cloud, on, off in clouds]
        shown += [(f"estimates/part_{k}", t <= end) for k, end in enumerate(until)]
        for name, on in shown:  # a key where it changes (a visibility track holds its last key)
            if visible.get(name) != on:
                meshcat.SetProperty(name, "visible", bool(on), time_in_recording=float(t))
                visible[name] = on
        for k in range(len(until)):
            meshcat.SetTransform(f"estimates/part_{k}", estimate_pose(series, k, float(t)),
                                 time_in_recording=float(t))
    for name, on in visible.items():  # every track to the last frame: the clips loop together
        meshcat.SetProperty(name, "visible", bool(on), time_in_recording=float(times[-1]))
    placed = sum(bool(p["placed"]) for p in metrics["picks"])
    heading = (f"{title or scenario.name}: {metrics.get('status', '')}, "
               f"{placed} of {len(metrics['picks'])} placed")
    html = finish_page(meshcat, heading, pick_legend(scenario, camera))
    Path(path).write_text(html, encoding="utf-8")
    return len(html.encode("utf-8"))
