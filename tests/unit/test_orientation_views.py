"""The views of a run with orientation (issue 19): ``angle.png`` listed in metrics.json and the
replay given the objects' orientations for its frame triads; a position run's figures stay the
four they were and its replay gets no orientation."""

import numpy as np

from ptint_drake.report.run_outputs import run_metrics, view_tasks
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.views.plots import run_figure

POSITION_FIGURES = ["axes.png", "errors.png", "joints.png", "paths3d.png"]


def test_a_position_run_keeps_its_four_figures(tmp_path):
    scenario = load_scenario("curve_b075_tf15")
    assert run_metrics(scenario, {"segments": []})["figures"] == POSITION_FIGURES
    tasks = view_tasks(scenario, {"t": np.zeros(3)}, {}, tmp_path)
    assert [task[1] for task in tasks] == ["axes", "errors", "paths3d", "joints", "replay"]
    assert tasks[-1][-1][3] is None  # the replay draws no triads


def test_an_orientation_run_adds_the_angle_figure(tmp_path):
    for name in ("conveyor_yaw", "curve_pose"):
        scenario = load_scenario(name)
        assert run_metrics(scenario, {"segments": []})["figures"] == POSITION_FIGURES + ["angle.png"]
        names = [task[1] for task in view_tasks(scenario, {}, {}, tmp_path, replay=False)]
        assert names == ["axes", "errors", "paths3d", "joints", "angle"]


def test_the_replay_gets_each_objects_true_orientation(tmp_path):
    scenario = load_scenario("conveyor_yaw")
    t = np.array([0.0, 1.0, 2.5])
    replay = view_tasks(scenario, {"t": t}, {}, tmp_path, figures=False)
    assert [task[1] for task in replay] == ["replay"]
    task, rotations = replay[0][-1][3]
    assert task == "top_down" and rotations.shape == (3, 3, 9)
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    np.testing.assert_allclose(rotations[1, 1], [c, -s, 0, s, c, 0, 0, 0, 1], atol=1e-12)  # Rz(30°)
    task, rotations = view_tasks(load_scenario("curve_pose"), {"t": t}, {}, tmp_path, figures=False)[0][-1][3]
    assert task == "pose" and not np.allclose(rotations[0, 0], rotations[2, 0])  # tumbling


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


def test_a_run_figure_title_carries_the_runs_verdict(tmp_path, monkeypatch):
    import matplotlib.figure

    titles = []
    suptitle = matplotlib.figure.FigureBase.suptitle
    monkeypatch.setattr(matplotlib.figure.FigureBase, "suptitle",
                        lambda fig, text, **kw: titles.append(text) or suptitle(fig, text, **kw))
    t = np.linspace(0.0, 2.0, 201)
    angle = 60.0 * np.exp(-5.0 * t)[:, None]
    metrics = {"segments": [{"start": 0.0, "tf": 0.5, "e_rot_tf_deg": 0.01}], "status": "missed",
               "criteria": {"e_rot_tf_deg": 2.0, "rot_hold_deg": 5.0}}
    run_figure("angle", {"t": t, "rot_angle_deg": angle}, metrics, tmp_path, "one part")
    assert titles and titles[-1].startswith("one part (missed): ")
