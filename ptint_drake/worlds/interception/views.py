"""What ``ptint run`` draws of an interception run: the figures (``figures.run_figure``) and the
Meshcat replay (``replay.write_replay``) with the conveyors and the objects' frames."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydrake.common.yaml import yaml_load_typed

from ptint_drake.config.schema import Scenario
from ptint_drake.config.yaml_io import dump_yaml
from ptint_drake.robot.plant import resolve_model
from ptint_drake.systems.task.orientation import target_rotation_values


def conveyor_belts(scenario: Scenario):
    """Belts to draw for linear targets: the stretch each object travels, ±0.1 m."""
    belts = []
    for ic in scenario.interceptions:
        lin = ic.target.linear
        if lin is None:
            continue
        a = np.asarray(lin.start)
        b = a + np.asarray(lin.velocity) * scenario.duration
        d = (b - a) / (np.linalg.norm(b - a) or 1.0)
        belts.append((a - 0.1 * d, b + 0.1 * d))
    return belts


def object_rotations(scenario: Scenario, targets: list, series: dict):
    """(task, rotations) for the replay's frame triads: each object's true orientation R_r
    (row-major, N × objects × 9) at the logged times ``series["t"]``; None for a position task."""
    if scenario.controller.task == "position":
        return None
    t = series["t"]
    rotations = np.array([[target_rotation_values(tg, tk)[0:9] for tg in targets] for tk in t.tolist()])
    return scenario.controller.task, rotations.reshape(len(t), len(targets), 9)


# the longest first: with two workers, the axes figure on one and the rest on the other;
# "angle" only for a task with orientation (figures.run_figure_stems)
VIEW_ORDER = ("axes", "errors", "paths3d", "joints", "angle", "replay")




def view_tasks(scenario: Scenario, targets: list, series: dict, metrics: dict, stage: Path, figures: bool,
               replay: bool, svg: bool) -> list[tuple]:
    """``draw_view`` arguments for a run's figures (PNG, and SVG when ``svg``) and its
    ``replay.html``, written in ``stage``."""
    from ptint_drake.views.plots import run_figure_stems  # noqa: PLC0415  (no matplotlib import)

    formats = ("png", "svg") if svg else ("png",)
    replay_args = (str(resolve_model(scenario.robot.model)), conveyor_belts(scenario),
                   scenario.robot.end_effector,
                   object_rotations(scenario, targets, series) if replay else None)
    stems = run_figure_stems(scenario.controller.task)
    names = [n for n in VIEW_ORDER if (n == "replay" and replay) or (n in stems and figures)]
    tasks = [(n, series, metrics, stage, scenario.name, replay_args if n == "replay" else (formats,))
             for n in names]
    if figures and scenario.measurement is not None and scenario.measurement.sensor == "rgbd":
        # the scenario as YAML text: a worker process draws each view (pickled arguments)
        tasks.append(("camera_frames", series, metrics, stage, scenario.name, (dump_yaml(scenario),)))
    return tasks


def draw_view(name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
    """One figure (``name`` in ``figures.RUN_FIGURES``, ``args`` = (formats,)) or the replay
    (``name == "replay"``, ``args`` = (model file, belts, end effector, ``object_rotations``))."""
    if name == "camera_frames":  # the RGB-D camera's frames (measurement.sensor: rgbd)
        from ptint_drake.worlds.interception.camera_frames import write_camera_frames  # noqa: PLC0415

        write_camera_frames(yaml_load_typed(schema=Scenario, data=args[0]), series, stage)
        return name
    if name == "replay":
        from ptint_drake.views.replay import write_replay  # noqa: PLC0415

        model_file, belts, end_effector, orientation = args
        write_replay(series, metrics, model_file, stage / "replay.html", conveyors=belts,
                     end_effector=end_effector, orientation=orientation,
                     title=f"{title}: {metrics.get('status', '')}")
        return name
    from ptint_drake.views.plots import run_figure  # noqa: PLC0415

    return run_figure(name, series, metrics, stage, title, *args)
