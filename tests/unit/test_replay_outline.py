"""``replay.outline_segments``: the estimate's outline in a camera pick's replay (issue 34)."""

import numpy as np

from ptint_drake.views.replay import outline_segments


def test_a_box_outline_is_its_twelve_edges():
    size = np.array([0.03, 0.04, 0.05])
    starts, ends = outline_segments("box", size)
    assert starts.shape == ends.shape == (3, 12)
    edges = np.abs(ends - starts)
    # four edges along each axis, each as long as the box is along it, none diagonal
    for axis in range(3):
        along = np.flatnonzero(edges[axis] > 0)
        assert len(along) == 4 and np.allclose(edges[axis, along], size[axis])
    assert np.all(np.count_nonzero(edges > 0, axis=0) == 1)
    assert np.allclose(np.abs(np.hstack([starts, ends])), 0.5 * size[:, None])  # on the corners


def test_a_cylinder_outline_is_two_rims_and_four_sides():
    starts, ends = outline_segments("cylinder", [0.04, 0.06], sides=24)
    assert starts.shape == (3, 2 * 24 + 4)
    points = np.hstack([starts, ends])
    assert np.allclose(np.hypot(points[0], points[1]), 0.02)
    assert set(np.round(points[2], 6)) == {-0.03, 0.03}
    vertical = np.abs(ends[2] - starts[2]) > 0
    assert np.count_nonzero(vertical) == 4 and np.allclose(ends[2, vertical] - starts[2, vertical], 0.06)
