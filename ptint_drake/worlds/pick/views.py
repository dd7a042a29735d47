"""What ``ptint run`` draws for a pick and place: a figure of the picks and a replay of the world.

The figures, ``pick_figure`` (``picks.png``) and ``estimate_figure`` (``estimates.png``, for a run
with an RGB-D camera), are drawn by ``worlds.pick.figures`` (its docstring says what each shows)
and re-exported here with ``GRASP_TAIL``, which the replay shares; ``timeline.png``, each part's
seen → scheduled → grasped → placed or failed, by ``worlds.pick.timeline``.  ``draw_pick_view``
draws one of them (or the replay, or the camera's frames) by name.

``write_pick_replay`` — ``replay.html``: the whole plant (arm, fingers, belts, parts, tray) rebuilt
from the scenario and replayed from its logged [q; v] at 30 frames per second into a Meshcat
recording, saved standalone with ``StaticHtml()`` (``replay``).  With an RGB-D camera it also shows
what the perception had (issue 34): the point cloud of each pick's first fit (magenta) and of its
grasp (violet) — the frame re-rendered, cropped and downsampled as the perception did
(``camera_frames.camera_views``) — from the frame's time until the pick's next cloud's frame (the
grasp's: ``GRASP_TAIL``; ``cloud_intervals``), and per part its
estimate (series ``part_estimate_k``, what the approach and the grasp aimed at) as a yellow outline
of its known shape with a frame triad, beside the simulated part, until ``GRASP_TAIL`` past its
pick's prescribed grasp (the part is in the hand then; the estimate runs on along the belt), and
each confirmed track of the perception as a small sphere of its own colour over its part at its
estimated centre, from its confirmation to its end (``track_markers``, issue 44).
The floor is drawn under the whole scene (``draw_pick_floor``), Meshcat's grid and axes hidden, and
the page loops with the time, a pause / play button and a legend (``replay.finish_page``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ptint_drake.worlds.pick.figures import GRASP_TAIL, estimate_figure, pick_figure  # noqa: F401 (re-exported)


def replay_world(scenario):
    """The scenario's whole pick world (arm, gripper, belts, parts, tray) in a plant with a
    MeshcatVisualizer on the shared Meshcat, cleared: (plant, visualizer, Meshcat, root context) —
    no dynamics, a logged plant state is set into it."""
    from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig  # noqa: PLC0415
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.views.replay import replay_visualizer  # noqa: PLC0415
    from ptint_drake.worlds.pick.cell import world_config  # noqa: PLC0415
    from ptint_drake.worlds.pick.station import _add_world  # noqa: PLC0415

    config = world_config(scenario)
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(time_step=config.time_step), builder)
    _add_world(plant, scene_graph, config)
    plant.Finalize()
    viz, meshcat, context = replay_visualizer(builder, scene_graph)
    return plant, viz, meshcat, context


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


def pick_legend(scenario, camera: bool, line: bool = False) -> list:
    """The legend of a pick replay (``replay.finish_page``); ``line``: a line's (tracks, no clouds)."""
    from ptint_drake.views.replay import FLOOR_COLOR, css_color  # noqa: PLC0415

    legend = [("rgba(40, 90, 200, 1)", "the parts, on their belts (dark), to the tray"),
              ("rgba(150, 150, 150, 1)", "the arm and its two-finger gripper")]
    if camera and not line:
        rgba = {k: "rgba({}, {}, {}, 1)".format(*(round(255 * c) for c in v[:3]))
                for k, v in CLOUD_RGBA.items()}
        legend += [(rgba["first_fit"], "magenta points: the depth camera's point cloud at the pick's "
                    "first fit (shown until the grasp's frame; it stays where the part was)"),
                   (rgba["grasp"], "violet points: the cloud at the prescribed grasp"),
                   ("rgba(255, 217, 0, 1)", "yellow outline and axes: the part's estimate, what the arm aims "
                    f"at (until {GRASP_TAIL:g} s past the grasp)")]
    if camera:
        legend.append(("rgba(26, 204, 230, 1)", "small spheres, a colour per track: the perception's "
                       "confirmed tracks, each over its part at its estimated centre"))
    legend.append((css_color(FLOOR_COLOR), "floor, 10 cm grid"))
    return legend


def draw_pick_floor(meshcat, plant, context) -> None:
    """The floor (``replay.draw_floor``: the plate, a 10 cm grid, Meshcat's grid hidden) under every
    body of the plant at its posed state, with a margin."""
    from pydrake.multibody.tree import BodyIndex  # noqa: PLC0415

    from ptint_drake.views.replay import draw_floor, floor_extent  # noqa: PLC0415

    plant_context = plant.GetMyContextFromRoot(context)
    points = np.array([plant.EvalBodyPoseInWorld(plant_context, plant.get_body(BodyIndex(i))).translation()
                       for i in range(1, plant.num_bodies())])
    draw_floor(meshcat, floor_extent(points, margin=0.2))


def draw_estimates(meshcat, scenario) -> None:
    """Per part k, ``estimates/part_{k}``: its known shape's outline (``replay.outline_segments``)
    in blue and a frame triad, posed by ``estimate_poses``."""
    from pydrake.geometry import Rgba  # noqa: PLC0415

    from ptint_drake.views.replay import draw_triad, outline_segments  # noqa: PLC0415

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
    from pydrake.math import RigidTransform  # noqa: PLC0415

    from ptint_drake.views.replay import finish_page  # noqa: PLC0415
    from ptint_drake.worlds.pick.track_markers import (  # noqa: PLC0415
        class_heights,
        confirmed_tracks,
        draw_track_markers,
        track_poses,
    )

    plant, viz, meshcat, context = replay_world(scenario)
    plant_context = plant.GetMyMutableContextFromRoot(context)
    times, states = series["replay_t"], series["plant_state"]
    plant.SetPositions(plant_context, states[0][:plant.num_positions()])
    draw_pick_floor(meshcat, plant, context)
    clouds, until, visible, tracks, heights = [], [], {}, [], []
    camera = scenario.measurement is not None and scenario.measurement.sensor == "rgbd"
    line = metrics.get("line")  # a line seen by the camera: its tracks, no declared part's estimate
    if camera and line is None:
        clouds = cloud_intervals(draw_camera_clouds(meshcat, scenario, series, metrics))
        draw_estimates(meshcat, scenario)
        until = estimate_shown_until(scenario, metrics)
    if camera:
        tracks = confirmed_tracks(series)
        heights = [c["height"] for c in line["classes"]] if line else class_heights(scenario)
        draw_track_markers(meshcat, tracks)
    meshcat.StartRecording(frames_per_second=30.0, set_visualizations_while_recording=False)
    for t, x in zip(times, states):
        plant.SetPositions(plant_context, x[:plant.num_positions()])
        context.SetTime(float(t))
        viz.ForcedPublish(viz.GetMyContextFromRoot(context))
        shown = [(cloud, on - 1e-6 <= t < off) for cloud, on, off in clouds]
        shown += [(f"estimates/part_{k}", t <= end) for k, end in enumerate(until)]
        for name, on, p in track_poses(tracks, heights, float(t)):  # the tracks' centres
            shown.append((name, on))
            meshcat.SetTransform(name, RigidTransform(p), time_in_recording=float(t))
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
    html = finish_page(meshcat, heading, pick_legend(scenario, camera, line is not None))
    Path(path).write_text(html, encoding="utf-8")
    return len(html.encode("utf-8"))


def draw_pick_view(name: str, scenario, series: dict, metrics: dict, stage: Path, title: str) -> str:
    """Draw the pick run's view ``name`` into ``stage`` (``PickWorld.draw_view``): ``picks``
    (``picks.png``), ``timeline`` (``timeline.png``: ``timeline``), ``estimates``
    (``estimates.png``), ``camera_frames`` (``frames/``) or the replay (``replay.html``)."""
    if name == "picks":
        pick_figure(series, metrics, stage / "picks.png", title)
    elif name == "timeline":
        from ptint_drake.worlds.pick.timeline import part_timelines, timeline_figure  # noqa: PLC0415

        camera = scenario.measurement is not None and scenario.measurement.sensor == "rgbd"
        lines = part_timelines([p.name for p in scenario.pick.parts], series, metrics, camera)
        timeline_figure(lines, metrics, stage / "timeline.png", title)
    elif name == "estimates":
        estimate_figure(series, metrics, *belt_frames(scenario), stage / "estimates.png", title)
    elif name == "camera_frames":
        from ptint_drake.worlds.pick.camera_frames import write_pick_camera_frames  # noqa: PLC0415

        write_pick_camera_frames(scenario, series, metrics, stage)
    else:
        write_pick_replay(scenario, series, metrics, stage / "replay.html", title=title)
    return name


def belt_frames(scenario) -> tuple[list, list]:
    """Per part: its belt's unit direction and its yaw symmetry (rad; ``part_fit.yaw_symmetry``)."""
    from ptint_drake.systems.perception.part_fit import yaw_symmetry  # noqa: PLC0415

    pick = scenario.pick
    belts = {b.name: np.asarray(b.direction, float) for b in pick.belts}
    return ([belts[p.belt] / np.linalg.norm(belts[p.belt]) for p in pick.parts],
            [yaw_symmetry(p.shape, p.size) for p in pick.parts])
