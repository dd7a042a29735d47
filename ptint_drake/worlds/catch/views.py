"""The catch run's replay (issue 46): ``replay.html``, what ``ptint run`` writes for a catch scenario.

The station's bodies (the iiwa 14, the WSG 50-110, the ball: ``station.add_arm_and_hand``,
``ball.AddBall``) posed from the run's logged plant state at 30 frames per second into a Meshcat
recording, saved standalone (``replay.finish_page``: it loops, with the time, a pause / play
button and a legend), and over them what the catch was made of:

- ``catch/ball_path``: the ball's true path, a thin orange line (the whole run);
- ``catch/estimate``: the ball's estimate (the station's estimator output, what the planner and
  the target read) as a translucent yellow sphere of the ball's size, from the first sample on;
- ``catch/catch_point``: the planner's catch point, a green sphere, from the first plan's time at
  that plan's point and moved to each revision's point at the revision's time;
  ``catch/catch_points``: the revised points joined in order (a green line, shown from the first
  plan: where the predicted catch point went as the estimate improved);
- ``catch/hand_path``: the hand's fingertip centre (forward kinematics of the logged posture), a
  blue line.

The floor is drawn under the scene (``replay.draw_floor``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

FPS = 30.0
BALL_RGBA = (1.0, 0.55, 0.1, 1.0)
ESTIMATE_RGBA = (1.0, 0.85, 0.0, 0.45)
CATCH_RGBA = (0.1, 0.75, 0.25, 1.0)
HAND_RGBA = (0.15, 0.45, 0.95, 1.0)
CATCH_MARK = 0.012  # m, the catch point's sphere radius


def replay_frames(times: np.ndarray) -> np.ndarray:
    """Indices of the logged samples the replay shows: the first at or after each 1 / ``FPS``."""
    times = np.asarray(times, float)
    marks = np.arange(0.0, times[-1] + 1e-9, 1.0 / FPS)
    return np.unique(np.minimum(np.searchsorted(times, marks - 1e-9), len(times) - 1))


def _replay_plant(scenario):
    """The station's arm, hand and ball in a plant with a MeshcatVisualizer on the shared Meshcat
    (cleared): (plant, visualizer, meshcat, root context)."""
    from pydrake.multibody.plant import AddMultibodyPlantSceneGraph  # noqa: PLC0415
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.views.replay import replay_visualizer  # noqa: PLC0415
    from ptint_drake.worlds.catch.ball import AddBall  # noqa: PLC0415
    from ptint_drake.worlds.catch.station import add_arm_and_hand  # noqa: PLC0415

    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    add_arm_and_hand(plant, scenario.catch.gripper)
    AddBall(plant)
    plant.Finalize()
    viz, meshcat, context = replay_visualizer(builder, scene_graph)
    return plant, viz, meshcat, context


def _line(meshcat, path: str, points: np.ndarray, rgba: tuple, width: float = 2.0) -> None:
    from pydrake.geometry import Rgba  # noqa: PLC0415

    meshcat.SetLine(path, np.asarray(points, float).T, width, Rgba(*rgba))


def hand_points(scenario, states: np.ndarray) -> np.ndarray:
    """The fingertip centre (N × 3) of each logged plant state (the arm's first 7 positions)."""
    from ptint_drake.worlds.catch.planner import Planner  # noqa: PLC0415
    from ptint_drake.worlds.catch.station import TIP, arm_plant  # noqa: PLC0415

    planner = Planner(arm_plant(), TIP, scenario.catch.beta)
    return np.array([planner.tip(x[:7])[0] for x in states])


def draw_catch_tracks(meshcat, scenario, series: dict, metrics: dict, frames: np.ndarray) -> list:
    """The lines and markers of the module docstring; returns the plans [(t_plan, point)]."""
    from pydrake.geometry import Rgba, Sphere  # noqa: PLC0415

    from ptint_drake.worlds.catch.ball import BALL_DIAMETER  # noqa: PLC0415

    states = np.asarray(series["plant_state"])
    _line(meshcat, "catch/ball_path", states[frames, 13:16], BALL_RGBA)
    _line(meshcat, "catch/hand_path", hand_points(scenario, states[frames]), HAND_RGBA)
    meshcat.SetObject("catch/estimate", Sphere(0.5 * BALL_DIAMETER), Rgba(*ESTIMATE_RGBA))
    plans = [(float(p["t_plan"]), np.asarray(p["point"], float)) for p in metrics["catch"]["plans"]]
    meshcat.SetObject("catch/catch_point", Sphere(CATCH_MARK), Rgba(*CATCH_RGBA))
    if len(plans) > 1:
        _line(meshcat, "catch/catch_points", np.array([p for _, p in plans]), CATCH_RGBA, 3.0)
    for name in ("catch/estimate", "catch/catch_point", "catch/catch_points"):
        meshcat.SetProperty(name, "visible", False)
    return plans


def write_catch_replay(scenario, series: dict, metrics: dict, path: Path, title: str = "") -> int:
    """Write ``replay.html`` (module docstring); returns its size in bytes."""
    from pydrake.math import RigidTransform  # noqa: PLC0415

    from ptint_drake.views.replay import draw_floor, finish_page, floor_extent  # noqa: PLC0415

    plant, viz, meshcat, context = _replay_plant(scenario)
    plant_context = plant.GetMyMutableContextFromRoot(context)
    times, states = np.asarray(series["t"]), np.asarray(series["plant_state"])
    estimate = np.asarray(series["estimate"])
    frames = replay_frames(times)
    draw_floor(meshcat, floor_extent(states[frames, 13:16], margin=0.3))
    plans = draw_catch_tracks(meshcat, scenario, series, metrics, frames)
    nq = plant.num_positions()
    meshcat.StartRecording(frames_per_second=FPS, set_visualizations_while_recording=False)
    visible = {}
    for i in frames:
        t = float(times[i])
        plant.SetPositions(plant_context, states[i][:nq])
        context.SetTime(t)
        viz.ForcedPublish(viz.GetMyContextFromRoot(context))
        made = [p for t_plan, p in plans if t_plan <= t + 1e-9]
        seen = bool(np.any(estimate[i, 3:6]))
        shown = {"catch/estimate": seen, "catch/catch_point": bool(made), "catch/catch_points": bool(made)}
        for name, on in shown.items():
            if visible.get(name) != on:
                meshcat.SetProperty(name, "visible", on, time_in_recording=t)
                visible[name] = on
        if seen:
            meshcat.SetTransform("catch/estimate", RigidTransform(estimate[i, 0:3]), time_in_recording=t)
        if made:
            meshcat.SetTransform("catch/catch_point", RigidTransform(made[-1]), time_in_recording=t)
    for name, on in visible.items():  # every track to the last frame: the clips loop together
        meshcat.SetProperty(name, "visible", on, time_in_recording=float(times[frames[-1]]))
    c = metrics["catch"]
    heading = f"{title or scenario.name}: throw {c['throw']}, {c['outcome']}, {len(plans)} plan(s)"
    html = finish_page(meshcat, heading, catch_legend())
    Path(path).write_text(html, encoding="utf-8")
    return len(html.encode("utf-8"))


def catch_legend() -> list:
    """The replay's legend (``replay.finish_page``)."""
    from ptint_drake.views.replay import FLOOR_COLOR, css_color  # noqa: PLC0415

    def rgb(c):
        return "rgba({}, {}, {}, 1)".format(*(round(255 * v) for v in c[:3]))

    return [(rgb(BALL_RGBA), "the ball and its true path"),
            (rgb(ESTIMATE_RGBA), "translucent yellow sphere: the ball's estimate (what the planner reads)"),
            (rgb(CATCH_RGBA), "green sphere: the predicted catch point, moved at each revision; "
             "green line: the revised points in order"),
            (rgb(HAND_RGBA), "blue line: the hand's fingertip centre"),
            ("rgba(150, 150, 150, 1)", "the iiwa 14 and its WSG 50-110"),
            (css_color(FLOOR_COLOR), "floor, 10 cm grid")]
