"""figures.envelope: the series a figure line is drawn from, thinned to what its pixel columns
can show (the first and last point, each column's minimum and maximum)."""

import numpy as np

from ptint_drake.views.plots import envelope


def _columns(x, x0, x1, n):
    return np.minimum(((x - x0) / (x1 - x0) * n).astype(int), n - 1)


def test_every_columns_extremes_the_ends_and_order_survive():
    rng = np.random.default_rng(4)
    x = np.sort(rng.uniform(0, 3, 20_000))
    y = np.sin(7 * x) + 0.3 * rng.normal(size=x.size)
    xs, ys = envelope(x, y, 400)
    assert len(xs) <= 2 * 400 + 2 and np.all(np.diff(xs) >= 0)
    assert (xs[0], xs[-1], ys[0], ys[-1]) == (x[0], x[-1], y[0], y[-1])
    col, col_s = _columns(x, x[0], x[-1], 400), _columns(xs, x[0], x[-1], 400)
    for c in range(400):
        assert ys[col_s == c].max() == y[col == c].max() and ys[col_s == c].min() == y[col == c].min()
    kept = set(zip(xs.tolist(), ys.tolist()))
    assert kept <= set(zip(x.tolist(), y.tolist()))  # points of the series, none made up


def test_an_error_curves_peak_and_its_dip_at_tf_survive_exactly():
    """|e(t)| of an interception: a start-up peak, a dip to its minimum at tf (log axis),
    a hold after it; 1 ms steps over 5 s on a 1200-pixel-wide figure."""
    t = np.arange(0.0, 5.0, 1e-3)
    tf = 1.5
    e = 0.05 * np.abs(1 - t / tf) ** 0.75 + 1e-7 + 2e-3 * np.exp(-((t - 0.05) / 0.01) ** 2)
    xs, ys = envelope(t, e, 1200)
    assert len(xs) < len(t)  # thinned: more points than columns
    k_peak, k_tf = int(np.argmax(e)), int(np.argmin(np.abs(t - tf)))
    assert e[k_tf] == e.min()
    for k in (k_peak, k_tf, 0, len(t) - 1):
        assert t[k] in xs and ys[np.searchsorted(xs, t[k])] == e[k]
    assert ys.max() == e.max() and ys.min() == e.min()


def test_short_series_are_left_whole():
    x = np.linspace(0, 1, 1000)
    y = np.cos(x)
    xs, ys = envelope(x, y, 400)  # at most 4 points a column: nothing to gain
    assert xs is x and ys is y
