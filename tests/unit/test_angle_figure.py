"""The orientation error figure (issue 19): ``angle.png`` for a task with orientation, listed in
metrics.json; a position run's figures stay the four they were."""

import numpy as np

from ptint_drake.figures import run_figure
from ptint_drake.run_outputs import run_metrics, view_tasks
from ptint_drake.scenario import load_scenario

POSITION_FIGURES = ["axes.png", "errors.png", "joints.png", "paths3d.png"]


def test_a_position_run_keeps_its_four_figures(tmp_path):
    scenario = load_scenario("curve_b075_tf15")
    assert run_metrics(scenario, {"segments": []})["figures"] == POSITION_FIGURES
    names = [task[0] for task in view_tasks(scenario, {}, {}, tmp_path)]
    assert names == ["axes", "errors", "paths3d", "joints", "replay"]


def test_an_orientation_run_adds_the_angle_figure(tmp_path):
    for name in ("conveyor_yaw", "curve_pose"):
        scenario = load_scenario(name)
        assert run_metrics(scenario, {"segments": []})["figures"] == POSITION_FIGURES + ["angle.png"]
        names = [task[0] for task in view_tasks(scenario, {}, {}, tmp_path, replay=False)]
        assert names == ["axes", "errors", "paths3d", "joints", "angle"]


def test_the_angle_figure_draws_each_objects_window(tmp_path):
    t = np.linspace(0.0, 2.0, 2001)
    angle = np.full((len(t), 2), np.nan)  # object 1 only from its segment's start (t = 0.8)
    angle[:, 0] = 60.0 * np.exp(-5.0 * t)
    angle[t >= 0.8, 1] = 30.0 * np.exp(-5.0 * (t[t >= 0.8] - 0.8))
    metrics = {"segments": [{"start": 0.0, "tf": 0.5, "e_rot_tf_deg": 0.01},
                            {"start": 0.8, "tf": 0.9, "e_rot_tf_deg": 0.0}],
               "criteria": {"e_rot_tf_deg": 2.0, "rot_hold_deg": 5.0}}
    assert run_figure("angle", {"t": t, "rot_angle_deg": angle}, metrics, tmp_path, "two parts") == "angle"
    assert (tmp_path / "angle.png").stat().st_size > 10_000
