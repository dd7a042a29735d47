"""Issue 33: picks.png shows the measured contact grip force (not the drives' command) and the grasp
state the gripper reported."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.axes  # noqa: E402
import numpy as np  # noqa: E402

from ptint_drake.systems.hand.gripper import GRASP_STATES  # noqa: E402
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


def _drawn_figure(monkeypatch):
    """Keep the figure a drawing function closes: [figure]."""
    import matplotlib.pyplot as plt

    kept = []
    monkeypatch.setattr(plt, "close", lambda fig=None: kept.append(fig))
    return kept


def test_the_picks_figure_has_its_outcome_labelled_axes_and_a_legend_for_every_line(run, tmp_path,
                                                                                      monkeypatch):
    result = run("conveyor_pick_place")
    kept = _drawn_figure(monkeypatch)
    pick_figure(result.series, result.metrics, tmp_path / "picks.png", "conveyor_pick_place")
    fig = kept[0]
    assert fig._suptitle.get_text() == "conveyor_pick_place: ok — 1 of 1 parts placed"
    outcome = fig.subfigs[0]._suptitle.get_text()
    assert "grasped at 1.70" in outcome and "prescribed 1.700 s" in outcome and "placed 0.16 mm" in outcome
    axes = fig.subfigs[0].axes
    in_legends = {t.get_text() for ax in axes if ax.get_legend() for t in ax.get_legend().get_texts()}
    for ax in axes:
        assert ax.get_ylabel(), ax.get_title()
        for line in ax.get_lines():
            assert not line.get_label().startswith("_") and line.get_label() in in_legends, line.get_label()
    assert {"prescribed grasp", "close command", "grasp state (right axis)", "drives' force"} <= in_legends
    assert all(ax.get_xlabel() == "t (s)" for ax in axes[-4:] if ax.get_subplotspec().is_last_row())
    width, height = fig.get_size_inches() * 100
    assert width >= 1200 and height >= 700  # 13 × 7.8 in at 100 dpi: the text at its size is readable
    assert min(t.get_fontsize() for ax in axes for t in [ax.title, ax.yaxis.label]) >= 10


def test_the_estimates_figure_explains_its_marks_and_why_the_fits_stop(tmp_path, monkeypatch):
    from conftest import run_cached

    from ptint_drake.worlds.pick.views import estimate_figure
    from ptint_drake.worlds.pick.views import belt_frames

    result = run_cached("conveyor_pick_place_rgbd")
    kept = _drawn_figure(monkeypatch)
    estimate_figure(result.series, result.metrics, *belt_frames(result.scenario), tmp_path / "estimates.png",
                    "conveyor_pick_place_rgbd")
    fig = kept[0]
    assert fig._suptitle.get_text().startswith("conveyor_pick_place_rgbd: ok")
    assert "the estimate at the grasp" in fig.subfigs[0]._suptitle.get_text()
    axes = fig.subfigs[0].axes
    legend = {t.get_text() for t in axes[-1].get_legend().get_texts()}
    assert {"estimate − truth", "each fit − truth", "a camera frame fitted", "prescribed grasp"} <= legend
    assert any(text.startswith("no fit: the arm hides the part") for text in legend)
    for ax in axes:
        assert ax.get_ylabel() and ax.get_xlabel() == "t (s)"
        # the estimate starts at the first fit: the nominal place before it is a note, not a line
        estimate = ax.get_lines()[0]
        assert estimate.get_xdata()[0] > 0.0
        lo, hi = ax.get_ylim()
        inside = (estimate.get_ydata() >= lo) & (estimate.get_ydata() <= hi)
        assert inside.mean() > 0.9
        assert any("before the first fit" in t.get_text() for t in ax.texts)
