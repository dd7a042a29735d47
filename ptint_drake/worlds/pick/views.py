"""What ``ptint run`` draws for a pick and place: a figure of the picks and a replay of the world.

``pick_figure`` — ``picks.png``: the run's verdict on top; per pick a block of four panels under
its outcome (grasp time against the prescribed, place error), over the task's time: the tool's distance to
the part (mm, log scale) and its angle from the top-down grasp (deg), the finger opening (mm) with
the grasp state the gripper reported (``systems.gripper.GraspObserver``: open … lost, a step line),
the grip force (N): the measured contact force squeezing the part (the smaller of the two pads'
normal forces, as ``peak_grip_force_N``) with the drives' force thin beside it, and the part's
height (mm); each attempt's prescribed grasp time (dashed) and close command (dotted) marked.

``estimate_figure`` — ``estimates.png``, for a run with an RGB-D camera: per pick (a row, under
its fits' count and the estimate's error at the grasp), the
part's estimate (what the pick aimed at) minus the truth (the simulated part) over time — along
its belt and across it (mm) and in yaw (deg, folded by the part's symmetry) — with each fit the
estimators were given (dots, at the frame's time: the fit minus the truth then), the frames'
times (grey ticks) and the prescribed grasp time (dashed) marked, each in the legend; up to 0.3 s
past the grasp (after it the part is in the hand); the estimate is drawn from the first fit on
(before it the pick aims at the part's nominal place: how far off, a note on the panel) and the
stretch from the last fit to the grasp is shaded (the arm over the part hides it: no fit, the
estimate rides its belt); the vertical range is that from the first fit to the grasp.

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


FONT_SIZE = 11  # pt, the pick figures' text (at 100 dpi: readable at the PNG's own size)


def pick_outcome(row: int, pick: dict) -> str:
    """One line: pick ``row``'s part and slot, its grasp time against the prescribed, its place."""
    grasp = ("never grasped" if pick["t_grasp"] is None else
             f"grasped at {pick['t_grasp']:.3f} s (prescribed {pick['t_grasp_prescribed']:.3f} s)")
    place = (f"placed {pick['place_error_mm']:.2f} mm, {pick['place_error_deg']:.2f}° from its slot"
             if pick["placed"] else "NOT placed")
    attempts = len(pick.get("attempt_details") or [pick])
    retried = f" after {attempts} attempts" if attempts > 1 else ""
    return f"pick {row} ({pick['part']} → slot {pick['slot']}): {grasp}{retried}, {place}"


def _mark_attempts(ax, pick: dict) -> None:
    """Each attempt's prescribed grasp time (dashed) and close command (dotted), labelled once."""
    for k, attempt in enumerate(pick.get("attempt_details") or [pick]):
        ax.axvline(attempt["t_grasp_prescribed"], color="k", ls="--", lw=0.9,
                   label="prescribed grasp" if k == 0 else None)
        ax.axvline(attempt["t_close_command"], color="tab:red", ls=":", lw=1.0,
                   label="close command" if k == 0 else None)


def _legend(ax, *others, loc: str = "best") -> None:
    """One legend for ``ax`` and its twin axes ``others``."""
    handles, labels = ax.get_legend_handles_labels()
    for other in others:
        h, lab = other.get_legend_handles_labels()
        handles, labels = handles + h, labels + lab
    ax.legend(handles, labels, fontsize=FONT_SIZE - 2, loc=loc, framealpha=0.85)


def pick_figure(series: dict, metrics: dict, path: Path, title: str = "") -> Path:
    """Draw ``picks.png`` (module docstring) from a pick run's series and metrics: per pick a
    block of four panels under its outcome (``pick_outcome``), the run's verdict on top."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    from ptint_drake.worlds.pick.metrics import rotation_of  # noqa: PLC0415
    from ptint_drake.worlds.pick.probe import PART_WIDTH  # noqa: PLC0415

    t, probe = series["t"], series["probe"]
    picks = metrics["picks"]
    with plt.rc_context({"font.size": FONT_SIZE}):
        fig = plt.figure(figsize=(13, 7.2 * len(picks) + 0.6), layout="constrained")
        placed = sum(bool(p["placed"]) for p in picks)
        fig.suptitle(f"{title or metrics.get('scenario', '')}: {metrics.get('status', '')} — "
                     f"{placed} of {len(picks)} parts placed", fontsize=FONT_SIZE + 3, fontweight="bold")
        blocks = np.atleast_1d(fig.subfigures(len(picks), 1))
        for row, (block_fig, pick) in enumerate(zip(blocks, picks)):
            block_fig.suptitle(pick_outcome(row, pick), fontsize=FONT_SIZE + 1)
            axes = block_fig.subplots(2, 2, sharex=True).ravel()
            k = pick["part_index"]
            block = probe[:, PART_WIDTH * k: PART_WIDTH * (k + 1)]
            distance = 1e3 * np.linalg.norm(block[:, 0:3] - probe[:, -7:-4], axis=1)
            x_axis = [1.0, 0.0, 0.0]
            angle = np.array([np.degrees(np.arccos(np.clip(
                (rotation_of(probe[j, -4:]) @ x_axis) @ (rotation_of(block[j, 3:7]) @ x_axis), -1.0, 1.0)))
                for j in range(len(t))])
            angle = np.minimum(angle, 180.0 - angle)  # the fingers' axis: a half turn is the same grasp
            opening = 1e3 * (series["gripper_state"][:, 0] + series["gripper_state"][:, 1])
            contact = np.min(series["grip_forces"][:, 2 * k: 2 * k + 2], axis=1)  # what squeezes the part
            drive = -np.mean(series["grip_force"], axis=1)

            ax = axes[0]  # the tool's distance to the part and its angle
            ax.plot(t, np.maximum(distance, 1e-3), lw=1.3, label="tool to part")
            ax.set_yscale("log")
            ax.set_ylabel("tool to part (mm, log)")
            twin = ax.twinx()
            twin.plot(t, angle, color="tab:orange", lw=1.0, label="angle from the top-down grasp")
            twin.set_ylabel("angle (deg)", color="tab:orange")
            _mark_attempts(ax, pick)
            ax.set_title(f"pick {row} ({pick['part']}): tool to part and its angle")
            _legend(ax, twin, loc="upper right")

            ax = axes[1]  # the fingers
            ax.plot(t, opening, lw=1.3, label="finger opening")
            ax.set_ylabel("opening (mm)")
            others = []
            if "grasp_state" in series:
                state = ax.twinx()
                _state_line(state, t, series["grasp_state"])
                others.append(state)
            _mark_attempts(ax, pick)
            ax.set_title(f"pick {row} ({pick['part']}): finger opening, grasp state")
            _legend(ax, *others, loc="center right")

            ax = axes[2]  # the grip
            ax.plot(t, contact, lw=1.3, label="contact grip (smaller pad force)")
            ax.plot(t, drive, color="0.6", lw=0.8, label="drives' force")
            ax.set_ylabel("force (N)")
            _mark_attempts(ax, pick)
            ax.set_title(f"pick {row} ({pick['part']}): contact grip force (N)")
            _legend(ax, loc="center left")

            ax = axes[3]  # the part's height
            ax.plot(t, 1e3 * block[:, 2], lw=1.3, label="part's height")
            ax.set_ylabel("height (mm)")
            _mark_attempts(ax, pick)
            ax.set_title(f"pick {row} ({pick['part']}): part height (mm)")
            _legend(ax, loc="upper right")
            for ax in axes[2:]:
                ax.set_xlabel("t (s)")
        fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


GRASP_TAIL = 0.3  # s, drawn past a pick's prescribed grasp in estimates.png


def _yaw(block: np.ndarray) -> np.ndarray:
    """The yaw of the row-major rotations in columns 3:12 of [x (3), R (9)] rows."""
    return np.arctan2(block[:, 6], block[:, 3])


def estimate_figure(series: dict, metrics: dict, directions: list, symmetries: list, path: Path,
                    title: str = "") -> Path:
    """Draw ``estimates.png`` (module docstring); ``directions``: per part its belt's unit
    direction, ``symmetries``: per part its yaw symmetry (rad; 0: none known, ``part_fit.yaw_symmetry``).
    The estimate is drawn from the first fit on (before it the pick aims at the part's nominal
    place: how far off that is is written on the panel); the stretch from the last fit to the
    grasp, where the arm over the part hides it and the estimate rides its belt, is shaded."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    from matplotlib.lines import Line2D  # noqa: PLC0415

    from ptint_drake.systems.perception.part_fit import fold_yaw  # noqa: PLC0415

    t, picks = np.asarray(series["t"]), metrics["picks"]
    with plt.rc_context({"font.size": FONT_SIZE}):
        fig = plt.figure(figsize=(14, 4.6 * len(picks) + 0.6), layout="constrained")
        fig.suptitle(f"{title or metrics.get('scenario', '')}: {metrics.get('status', '')} — the part's "
                     "estimate (what the pick aims at) minus the simulated part", fontsize=FONT_SIZE + 2,
                     fontweight="bold")
        blocks = np.atleast_1d(fig.subfigures(len(picks), 1))
        for row, (block_fig, pick) in enumerate(zip(blocks, picks)):
            axes = block_fig.subplots(1, 3)
            k = pick["part_index"]
            true, estimate, fit = (np.asarray(series[f"{name}_{k}"])
                                   for name in ("part_true", "part_estimate", "fit"))
            u = np.asarray(directions[k], float)
            across = np.array([-u[1], u[0], 0.0])
            grasp = pick["t_grasp_prescribed"]
            keep = t <= grasp + GRASP_TAIL
            error = estimate[:, 0:3] - true[:, 0:3]
            stamps, first = np.unique(fit[:, 0], return_index=True)
            valid = fit[first, 4] > 0.5
            stamps, first = stamps[valid], first[valid]
            at = np.searchsorted(t, stamps).clip(0, len(t) - 1)  # the truth at each frame's time
            fit_error = fit[first, 1:4] - true[at, 0:3]
            # R[1, 0], R[0, 0] after [stamp, x, y, z, valid]
            fit_yaw = np.arctan2(fit[first, 8], fit[first, 5])
            dyaw, fit_dyaw = _yaw(estimate) - _yaw(true), fit_yaw - _yaw(true[at])
            # (a part of any yaw, symmetry 0: fold_yaw's 0 for each)
            yaw_error = np.degrees(fold_yaw(dyaw, symmetries[k]) + 0.0 * dyaw)
            fit_yaw_error = np.degrees(fold_yaw(fit_dyaw, symmetries[k]) + 0.0 * fit_dyaw)
            panels = (("along the belt", "mm", 1e3 * error @ u, 1e3 * fit_error @ u),
                      ("across the belt", "mm", 1e3 * error @ across, 1e3 * fit_error @ across),
                      ("yaw", "deg", yaw_error, fit_yaw_error))
            shown = stamps <= grasp + GRASP_TAIL
            first_fit = stamps[0] if len(stamps) else None
            last_fit = stamps[shown][-1] if np.any(shown) else None
            fitted = keep & (t >= (first_fit if first_fit is not None else np.inf))
            at_grasp = ("never fitted" if pick.get("estimate_error_mm") is None else
                        f"at the grasp {pick['estimate_error_mm']:.2f} mm, "
                        f"{pick['estimate_error_deg']:.2f}° off")
            block_fig.suptitle(f"pick {row} ({pick['part']}): {len(stamps[shown])} fits, the estimate "
                               f"{at_grasp}; {'placed' if pick['placed'] else 'NOT placed'}",
                               fontsize=FONT_SIZE + 1)
            for ax, (label, unit, values, fits) in zip(axes, panels):
                ax.plot(t[fitted], values[fitted], lw=1.3, label="estimate − truth")
                ax.plot(stamps[shown], fits[shown], ".", ms=4, color="tab:orange", label="each fit − truth")
                if np.any(fitted):
                    lo, hi = np.percentile(np.r_[values[fitted & (t <= grasp)], fits[shown]], [1, 99])
                    pad = max(0.25 * (hi - lo), 0.2)
                    ax.set_ylim(min(lo, 0.0) - pad, max(hi, 0.0) + pad)
                ax.axhline(0.0, color="0.5", lw=0.5)
                for s_ in stamps[shown]:
                    ax.axvline(s_, ymin=0.0, ymax=0.04, color="0.4", lw=0.7)
                if last_fit is not None and last_fit < grasp:
                    ax.axvspan(last_fit, grasp, color="0.92", zorder=0)
                ax.axvline(grasp, color="k", ls="--", lw=0.9)
                if first_fit is not None and first_fit > t[0]:
                    before = values[0]
                    ax.text(0.02, 0.97, f"before the first fit ({first_fit:.2f} s):\nthe nominal place, "
                            f"{before:+.1f} {unit}", transform=ax.transAxes, va="top", fontsize=FONT_SIZE - 2,
                            color="0.3")
                ax.set_title(f"estimate error {label} ({unit})")
                ax.set_ylabel(f"{label} ({unit})")
                ax.set_xlabel("t (s)")
                ax.set_xlim(t[0], grasp + GRASP_TAIL)
            extra = [Line2D([], [], color="0.4", marker="|", ls="none", ms=10,
                            label="a camera frame fitted"),
                     Line2D([], [], color="k", ls="--", lw=0.9, label="prescribed grasp"),
                     matplotlib.patches.Patch(color="0.92", label="no fit: the arm hides the part,\n"
                                              "the estimate rides its belt")]
            handles, labels = axes[0].get_legend_handles_labels()
            axes[-1].legend(handles + extra, labels + [h.get_label() for h in extra],
                            fontsize=FONT_SIZE - 2, loc="upper left", bbox_to_anchor=(1.02, 1.0))
        fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _state_line(ax, t: np.ndarray, codes: np.ndarray) -> None:
    """The gripper's reported grasp state over time, a step line on its own axis (open … lost)."""
    from ptint_drake.systems.gripper import GRASP_STATES  # noqa: PLC0415

    ax.step(t, codes, where="post", color="tab:green", lw=0.9, label="grasp state (right axis)")
    ax.set_yticks(range(len(GRASP_STATES)), GRASP_STATES, fontsize=FONT_SIZE - 2, color="tab:green")
    ax.set_ylim(-0.5, len(GRASP_STATES) - 0.5)
    ax.set_ylabel("grasp state", color="tab:green")


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
