"""``figure_grid.place_grid``: a grid laid out once, nothing clipped, nothing overlapping."""

import numpy as np

from ptint_drake.views.plot_grid import place_grid
from ptint_drake.views.plots import new_figure


def _grid_figure():
    """A 3 × 2 grid like the run's axes figure, with the decorations that take room: wide tick
    labels (−30000), y offset texts on the top and a lower row (values 0.5 ± 1e-6), column
    titles, y labels on the first column, x labels on the bottom row, a suptitle and a legend
    at the bottom."""
    fig = new_figure((7, 6))
    axes = fig.subplots(3, 2, sharex=True)
    t = np.linspace(0.0, 3.0, 200)
    rows = (0.5 + 1e-6 * np.sin(t), 0.5 + 1e-6 * np.sin(5 * t), 3e4 * np.cos(3 * t))
    for r, y in enumerate(rows):
        for c in range(2):
            axes[r, c].plot(t, y * (1 + c), label="robot")
            axes[r, c].axvline(1.5, ls="--", label="$t_f$")
        axes[r, 0].set_ylabel(f"row {r} [m/s²]")
    for c in range(2):
        axes[0, c].set_title("XY"[c], y=1.0)
        axes[-1, c].set_xlabel("time [s]")
    legend = fig.legend(*axes[0, 0].get_legend_handles_labels(), loc="lower center", ncol=2)
    suptitle = fig.suptitle("a title: robot vs target per axis")
    place_grid(fig, axes, suptitle, legend)
    return fig, axes, suptitle, legend


def test_nothing_leaves_the_figure_or_overlaps():
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415

    fig, axes, suptitle, legend = _grid_figure()
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    assert axes[0, 0].yaxis.offsetText.get_text() and axes[1, 0].yaxis.offsetText.get_text()
    boxes = [ax.get_tightbbox(renderer) for ax in axes.flat]
    others = [suptitle.get_window_extent(renderer), legend.get_window_extent(renderer)]
    for box in boxes + others:
        assert box.x0 >= 0 and box.y0 >= 0 and box.x1 <= fig.bbox.width and box.y1 <= fig.bbox.height
    everything = boxes + others
    for i, a in enumerate(everything):
        for b in everything[i + 1:]:
            assert not a.overlaps(b), (a, b)
    for ax in axes[0]:  # the titles clear the offset texts
        offset = ax.yaxis.offsetText.get_window_extent(renderer)
        assert not ax.title.get_window_extent(renderer).overlaps(offset)
    # the axis labels sit where the draw would put them: beside their own tick labels
    for ax in axes[:, 0]:
        ticks = max(t.get_window_extent(renderer).x0 for t in ax.get_yticklabels() if t.get_text())
        assert ax.yaxis.label.get_window_extent(renderer).x1 < ticks
