"""The layout of a figure's grid of axes, measured once (``place_grid``).

matplotlib's constrained layout measures every axis of every panel (its tick labels, labels,
offset text) twice before a figure is drawn, and the draw measures them again: for the run's
12-panel ``axes`` figure those two layout passes were about half of the figure's cost.  A grid
made by ``Figure.subplots`` with ``sharex=True`` needs less: the font sizes fix its vertical
margins (suptitle, column titles, the bottom row's tick labels and label, a figure legend at
the bottom), and the widths of the y tick labels, known once the panels' heights are, fix the
horizontal ones.  ``place_grid`` measures exactly those artists, once, at the figure's dpi, sets
the grid's ``subplots_adjust`` parameters and pins the axis labels where the draw would put
them (so that the draw does not measure the tick labels again to place them); the figure is
then drawn without a layout engine (``figures.save(..., laid_out=True)``).
"""

from __future__ import annotations

import numpy as np

PAD_PT = 4.0  # space between neighbouring decorations and at the figure's edges [points]
GAP_PT = 12.0  # between two rows of panels (their x tick marks, peak markers on the frame) [points]


def place_grid(fig, axes, suptitle=None, legend=None) -> None:
    """Position ``axes`` (``fig.subplots``' rows × columns, x shared) so that nothing outside
    the panels overlaps or leaves the figure: ``suptitle`` (its ``Text``) on top, the top
    row's titles, every panel's y tick labels and offset text (e.g. ``1e3``), the first
    column's y labels, the bottom row's x tick labels and labels, and ``legend`` (a figure
    legend at the lower centre) below them, the last column's legends where they reach out
    to the right (``bbox_to_anchor=(1.01, 1.0)``); ``PAD_PT`` between any two of them, ``GAP_PT``
    between two rows.  Every axis label is then pinned beside its own tick labels, and the
    titles above the top row's offset texts if there are any (pin a title's place with
    ``set_title(..., y=1.0)``: otherwise the draw measures the panel again to place it)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415

    renderer = FigureCanvasAgg(fig).get_renderer()
    grid = np.asarray(axes, dtype=object)
    grid = grid.reshape(grid.shape[0] if grid.ndim else 1, -1)
    width, height = fig.bbox.width, fig.bbox.height
    pad, row_gap = PAD_PT * fig.dpi / 72.0, GAP_PT * fig.dpi / 72.0
    fig.subplots_adjust(left=0.1, right=0.95, bottom=0.1, top=0.9)
    head = pad  # vertical: fixed by the fonts (and any y offset text)
    if suptitle is not None:  # at the top edge, ``PAD_PT`` below it
        suptitle.set_y(1.0 - pad / height)
        head += suptitle.get_window_extent(renderer).height + pad
    titles = max(_beyond(ax, ax.title, renderer)[3] for ax in grid[0])
    below = {ax: _tick_reach(ax, ax.xaxis, renderer, 1) for ax in grid[-1]}
    bottom = pad + max(below[ax] + _label_depth(ax.xaxis, renderer) for ax in grid[-1])
    bottom += legend.get_window_extent(renderer).y1 + pad if legend is not None else 0.0
    offsets = np.zeros(2)  # room for a y offset text (e.g. "1e3") above the top row, the others
    for _ in range(3):  # again only when an offset text appears where there was no room for it
        top = head + titles + offsets[0] + pad  # the titles go above an offset text
        _adjust(fig, grid.shape, (None, width - pad), (bottom, height - top), (None, row_gap + offsets[1]))
        left_of = {ax: _tick_reach(ax, ax.yaxis, renderer, 0) for ax in grid.flat}  # the y ticks
        found = [max((_offset_height(ax.yaxis, renderer) for ax in rows.flat), default=0.0)
                 for rows in (grid[:1], grid[1:])]
        if np.all(found <= offsets):
            break
        offsets = np.maximum(offsets, found)
    left = pad + max(left_of[ax] + _label_depth(ax.yaxis, renderer) for ax in grid[:, 0])
    gap = pad + max((left_of[ax] + _label_depth(ax.yaxis, renderer) for ax in grid[:, 1:].flat), default=0.0)
    legends = [_beyond(ax, ax.get_legend(), renderer)[2] for ax in grid[:, -1] if ax.get_legend()]
    right = pad + max([_tick_reach(ax, ax.xaxis, renderer, 2) for ax in grid[-1]] + legends)
    _adjust(fig, grid.shape, (left, width - right), (bottom, height - top), (gap, row_gap + offsets[1]))
    for ax in grid[0]:
        ax.title.set_y(1.0 + offsets[0] / ax.bbox.height)
    for ax in grid.flat:  # where the draw would put each label: ``labelpad`` beyond its tick labels
        ax.yaxis.set_label_coords(-(left_of[ax] + _labelpad(ax.yaxis)) / ax.bbox.width, 0.5)
        ax.xaxis.set_label_coords(0.5, -(below.get(ax, 0.0) + _labelpad(ax.xaxis)) / ax.bbox.height)


def _adjust(fig, shape, xs, ys, gaps) -> None:
    """``subplots_adjust`` from pixels: the grid spans ``xs`` × ``ys`` (None: unchanged), with
    ``gaps`` (horizontal, vertical) between panels."""
    rows, cols = shape
    w, h = fig.bbox.width, fig.bbox.height
    p = fig.subplotpars
    x0, x1 = (p.left * w if xs[0] is None else xs[0]), xs[1]
    y0, y1 = ys
    gx = p.wspace * (x1 - x0) / (cols + p.wspace * (cols - 1)) if gaps[0] is None else gaps[0]
    gy = gaps[1]
    panel_w = (x1 - x0 - gx * (cols - 1)) / cols
    panel_h = (y1 - y0 - gy * (rows - 1)) / rows
    fig.subplots_adjust(left=x0 / w, right=x1 / w, bottom=y0 / h, top=y1 / h,
                        wspace=gx / panel_w, hspace=gy / panel_h)


def _beyond(ax, artist, renderer) -> tuple[float, float, float, float]:
    """How far ``artist`` reaches beyond ``ax``'s frame: (left, bottom, right, top) in pixels
    (0 where it stays inside; all 0 for an empty text)."""
    if hasattr(artist, "get_text") and not artist.get_text():
        return 0.0, 0.0, 0.0, 0.0
    a, box = artist.get_window_extent(renderer), ax.bbox
    return max(box.x0 - a.x0, 0.0), max(box.y0 - a.y0, 0.0), max(a.x1 - box.x1, 0.0), max(a.y1 - box.y1, 0.0)


def _tick_reach(ax, axis, renderer, side: int) -> float:
    """How far the tick labels a draw shows on ``axis`` reach beyond ``ax``'s frame on
    ``side`` (0 left, 1 bottom, 2 right, 3 top) [pixels]; computes the ticks (one locator and
    formatter call, and the ticks the draw then reuses)."""
    locs = axis.get_majorticklocs()
    axis.get_majorticklabels()  # sets the labels' texts and positions
    lo, hi = sorted(axis.get_view_interval())
    slack = 1e-9 * (hi - lo)
    return max((_beyond(ax, tick.label1, renderer)[side]
                for tick, loc in zip(axis.get_major_ticks(len(locs)), locs)
                if lo - slack <= loc <= hi + slack and tick.label1.get_visible()), default=0.0)


def _labelpad(axis) -> float:
    """The axis' ``labelpad`` [pixels]."""
    return axis.labelpad * axis.get_figure(root=True).dpi / 72.0


def _label_depth(axis, renderer) -> float:
    """The room the axis label takes beyond its tick labels (0 without one) [pixels]."""
    if not axis.label.get_text():
        return 0.0
    box = axis.label.get_window_extent(renderer)
    return _labelpad(axis) + (box.width if axis.axis_name == "y" else box.height)


def _offset_height(axis, renderer) -> float:
    """How far a y axis' offset text (e.g. "1e3") reaches above its panel, 0 without one: the
    draw puts it ``OFFSETTEXTPAD`` points above the frame [pixels]."""
    text, offset = axis.offsetText, axis.get_major_formatter().get_offset()  # of the ticks computed
    if not (text.get_visible() and offset):
        return 0.0
    text.set_text(offset)  # as the draw will
    return axis.OFFSETTEXTPAD * renderer.dpi / 72.0 + text.get_window_extent(renderer).height
