"""Issue 33: picks.png shows the measured contact grip force (not the drives' command) and the grasp
state the gripper reported."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.axes  # noqa: E402
import numpy as np  # noqa: E402

from ptint_drake.systems.gripper import GRASP_STATES  # noqa: E402
from ptint_drake.worlds.pick.views import pick_figure  # noqa: E402


def test_the_picks_figure_draws_the_contact_grip_and_the_grasp_state(run, tmp_path, monkeypatch):
    result = run("conveyor_pick_place")
    series, metrics = result.series, result.metrics
    drawn, steps = [], []
    plot, step = matplotlib.axes.Axes.plot, matplotlib.axes.Axes.step
    monkeypatch.setattr(matplotlib.axes.Axes, "plot",
                        lambda ax, x, y, *a, **k:
                         drawn.append((ax, np.asarray(y))) or plot(ax, x, y, *a, **k))
    monkeypatch.setattr(matplotlib.axes.Axes, "step",
                        lambda ax, x, y, *a, **k:
                        steps.append((ax, np.asarray(y))) or step(ax, x, y, *a, **k))
    path = pick_figure(series, metrics, tmp_path / "picks.png")
    assert path.stat().st_size > 10_000
    contact = np.min(series["grip_forces"][:, 0:2], axis=1)
    lines = [y for ax, y in drawn if "contact grip force" in ax.get_title()]  # titled after the plot
    assert np.array_equal(lines[0], contact)  # the first line of the panel: the measured contact
    assert abs(np.max(lines[0]) - metrics["picks"][0]["peak_grip_force_N"]) < 1e-6
    assert np.array_equal(steps[0][1], series["grasp_state"])
    assert [t.get_text() for t in steps[0][0].get_yticklabels()] == list(GRASP_STATES)
