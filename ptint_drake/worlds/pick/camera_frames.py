"""``write_pick_camera_frames`` — what a pick run's RGB-D camera saw at each pick's first fit and
at its prescribed grasp, as PNG files (issue 34, "seeing what the camera sees").

The pick station (with its camera) and the perception are built again from the scenario; at each
instant the whole plant is posed from the run's replay state nearest in time (``replay_t``,
``plant_state``: every 33 ms), the camera renders, the perception fits that frame, and
``frames/pick{i}_first_fit_*.png`` / ``frames/pick{i}_grasp_*.png`` are written
(``systems.perception.frame_images``: every fit as a green or red cross with its yaw, and the
part's estimate at that time — what the pick aimed at — as a blue one).  Re-rendering costs
~0.3–0.5 s for VTK's start-up plus a few ms per frame.

``camera_views`` yields each instant's view (images, fits, the cloud the fits used, the estimate);
the replay (``views.write_pick_replay``) draws its clouds from it too.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.config.schema import Scenario
from ptint_drake.systems.perception.frame_images import write_frame
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose
from ptint_drake.worlds.pick.camera import AddPartEstimates
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.station import MakePickStation

ESTIMATE = (40, 120, 255)  # the estimate's colour in the frames (RGB)


def first_fit_time(series: dict, part: int):
    """The stamp of part ``part``'s first fit the estimators were given (None: never fitted)."""
    fit = np.asarray(series[f"fit_{part}"])
    valid = fit[:, 4] > 0.5
    return float(fit[valid, 0][0]) if np.any(valid) else None


def pick_instants(series: dict, metrics: dict) -> list[tuple[str, int, float]]:
    """(label, part index, time): each pick's first fit (when it has one) and prescribed grasp."""
    out = []
    for i, pick in enumerate(metrics["picks"]):
        k = pick["part_index"]
        first = first_fit_time(series, k)
        if first is not None:
            out.append((f"pick{i}_first_fit", k, first))
        out.append((f"pick{i}_grasp", k, float(pick["t_grasp_prescribed"])))
    return out


@dataclass
class CameraView:
    """What the camera saw at one instant of ``pick_instants``: the frame re-rendered at the replay
    state nearest in time ``t``, the perception's fits and cloud of it, and the part's estimate then."""

    label: str
    part: int
    t: float  # s, the replay state's time (the frame's)
    color: np.ndarray  # H × W × 3, uint8
    depth: np.ndarray  # H × W, m
    fits: list  # part_fit.PartFit of the frame
    points: np.ndarray  # N × 3, world: the cloud the fits used (``PartPoseEstimator.frame_points``)
    estimate: np.ndarray  # [x (3), R (9) row-major]: the part's estimate at t (what the pick aimed at)


def camera_views(scenario: Scenario, series: dict, metrics: dict) -> Iterator[CameraView]:
    """The camera's view at each of ``pick_instants`` (module docstring), one after the other."""
    builder = DiagramBuilder()
    station = MakePickStation(world_config(scenario), scenario.measurement)
    system = builder.AddNamedSystem("pick_station", station.diagram)
    estimator = AddPartEstimates(builder, system.GetOutputPort("depth_image"), scenario).estimator
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    plant_context = station.plant.GetMyMutableContextFromRoot(context)
    station_context = system.GetMyContextFromRoot(context)
    estimator_context = estimator.GetMyContextFromRoot(context)
    replay_t, states = np.asarray(series["replay_t"]), np.asarray(series["plant_state"])
    times = np.asarray(series["t"])
    nq = station.plant.num_positions()
    for label, part, t in pick_instants(series, metrics):
        j = int(np.argmin(np.abs(replay_t - t)))
        context.SetTime(float(replay_t[j]))
        station.plant.SetPositions(plant_context, states[j, :nq])
        color = np.array(system.GetOutputPort("color_image").Eval(station_context).data)[:, :, :3]
        depth = np.array(system.GetOutputPort("depth_image").Eval(station_context).data)[:, :, 0]
        cloud = estimator.GetInputPort("point_cloud").Eval(estimator_context)
        estimate = np.asarray(series[f"part_estimate_{part}"])[int(np.argmin(np.abs(times - replay_t[j])))]
        yield CameraView(label, part, float(replay_t[j]), color, depth, estimator.fit_frame(cloud),
                         estimator.frame_points(cloud), estimate)


def write_pick_camera_frames(scenario: Scenario, series: dict, metrics: dict, stage: Path) -> list[str]:
    """The frames of the module docstring, in ``stage / "frames"``; returns their names."""
    X_WC, info = camera_pose(scenario.measurement.camera), camera_info(scenario.measurement.camera)
    folder = stage / "frames"
    folder.mkdir(parents=True, exist_ok=True)
    names = []
    for view in camera_views(scenario, series, metrics):
        yaw = float(np.arctan2(view.estimate[6], view.estimate[3]))  # R[1, 0], R[0, 0] of the row-major R
        pick, instant = view.label.split("_", 1)
        title = (f"{scenario.name}: {pick.replace('pick', 'pick ')} ({scenario.pick.parts[view.part].name}), "
                 f"{instant.replace('_', ' ')}, t = {view.t:.3f} s")
        names += write_frame(folder, view.label, view.color, view.depth, view.fits, X_WC, info,
                             [(view.estimate[0:3], yaw, ESTIMATE)], title=title,
                             marks="crosses: green = good fit, red = rejected, blue = the estimate aimed at")
    return names
