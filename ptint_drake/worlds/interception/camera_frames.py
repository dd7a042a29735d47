"""``write_camera_frames`` — what the RGB-D camera saw at a few instants of a run, as PNG files.

For each segment at its start, half-way and at tf: the station is re-posed from the run's series
(the arm's logged joint angles at the nearest logged time; the objects by their motion), the
camera renders, and ``frames/seg{i}_{when}_color.png`` (the colour image with every fit's centre
drawn: a green cross for a good fit, a red one for a rejected fit, with its symmetric yaw as a
line) and ``..._depth.png`` (the noisy depth, near = bright, missing pixels black) are written
(``systems.perception.frame_images``).
Re-rendering after the run costs ~0.3 s for VTK's start-up plus a few ms per frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.systems.framework import Context, Diagram, DiagramBuilder, System

from ptint_drake.config.schema import Scenario
from ptint_drake.systems.perception.frame_images import write_frame
from ptint_drake.systems.perception.part_pose_estimator import AddRgbdPerception
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose
from ptint_drake.worlds.interception.station import MakeStation, Station


def _instants(scenario: Scenario) -> list[tuple[str, float]]:
    out = []
    for i, ic in enumerate(scenario.interceptions):
        for label, t in (("start", ic.start), ("half", ic.start + 0.5 * ic.tf), ("tf", ic.start + ic.tf)):
            out.append((f"seg{i}_{label}", t))
    return out


@dataclass
class RgbdView:
    """A scenario's station (with its camera) and the perception reading its depth image, in one
    diagram with a context: what the frames here and ``scripts/rgbd_bench.py`` render and fit."""

    station: Station
    system: System  # the station's diagram inside ``diagram``
    estimator: System  # the perception's part-pose estimator (``fit_frame``, ``point_cloud`` input)
    diagram: Diagram
    context: Context


def build_rgbd_view(scenario: Scenario) -> RgbdView:
    """The station and its perception of an ``rgbd`` scenario, built with a default context."""
    station = MakeStation(scenario)
    builder = DiagramBuilder()
    system = builder.AddSystem(station.diagram)
    _, estimator = AddRgbdPerception(builder, system.GetOutputPort("depth_image"), scenario.measurement,
                                     station.true_targets, scenario.duration)
    diagram = builder.Build()
    return RgbdView(station, system, estimator, diagram, diagram.CreateDefaultContext())


def write_camera_frames(scenario: Scenario, series: dict, stage: Path) -> list[str]:
    """The frames of the module docstring, in ``stage / "frames"``; returns their names."""
    view = build_rgbd_view(scenario)
    station, system, estimator, context = view.station, view.system, view.estimator, view.context
    plant_context = station.plant.GetMyMutableContextFromRoot(context)
    station_context = system.GetMyContextFromRoot(context)
    X_WC, info = camera_pose(scenario.measurement.camera), camera_info(scenario.measurement.camera)
    folder = stage / "frames"
    folder.mkdir(parents=True, exist_ok=True)
    times, q = np.asarray(series["t"]), np.asarray(series["q"])
    names = []
    for label, t in _instants(scenario):
        k = int(np.argmin(np.abs(times - t)))
        context.SetTime(float(times[k]))
        station.plant.SetPositions(plant_context, q[k])
        color = np.array(system.GetOutputPort("color_image").Eval(station_context).data)[:, :, :3]
        depth = np.array(system.GetOutputPort("depth_image").Eval(station_context).data)[:, :, 0]
        fits = estimator.fit_frame(estimator.GetInputPort("point_cloud").Eval(
            estimator.GetMyContextFromRoot(context)))
        segment, instant = label.split("_", 1)
        when = {"start": "start", "half": "tf/2", "tf": "tf"}[instant]
        title = f"{scenario.name}: segment {segment[3:]} at its {when}, t = {times[k]:.3f} s"
        names += write_frame(folder, label, color, depth, fits, X_WC, info, title=title)
    return names
