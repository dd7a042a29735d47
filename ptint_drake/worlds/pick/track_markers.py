"""The perception's confirmed tracks in the pick replay (issue 44): per track a small sphere of its
own colour at its estimated centre, moving with it over the run.

``confirmed_tracks`` reads the perception's tracks log (series ``tracks_t`` / ``tracks``,
``systems.perception.track_system``: per frame [stamp, per slot: id, bound part, took a fit,
centre (3), class]) frame by frame: a track counts as confirmed from the frame of its
``tracks.CONFIRM``-th fit on (what the tracker itself requires), and is shown until the last frame
it is in the log (it ends when its part leaves the view or stays unseen too long).  Its centre in a
frame is what the log holds: the fit it took, else its filter's prediction (coasting under the arm).

``draw_track_markers`` puts each one's sphere at ``tracks/track_{id}`` (hidden), ``track_poses``
says where each is at a replay time and whether it is shown.  The sphere sits ``MARK_ABOVE`` over
the part's top (the class's height, from the catalog ``part_tracks.catalog``), where the part does
not hide it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ptint_drake.config.part_shape import part_height
from ptint_drake.systems.perception.track_system import ROW
from ptint_drake.systems.perception.tracks import CONFIRM, MAX_TRACKS

MARK_RADIUS = 0.006  # m
MARK_ABOVE = 0.012  # m over the part's top face
TRACK_RGB = ((0.1, 0.8, 0.9), (1.0, 0.5, 0.0), (0.3, 0.9, 0.2), (0.9, 0.2, 0.9), (1.0, 0.9, 0.1),
             (0.2, 0.4, 1.0))  # cyan, orange, green, pink, yellow, blue: seen beside the blue parts


@dataclass
class TrackPath:
    """One confirmed track: its id, the class it voted for at its last frame, and per frame from
    its confirmation on the frame's time and its centre (N × 3)."""

    id: int
    kind: int
    times: np.ndarray
    centres: np.ndarray


def _frames(series: dict) -> np.ndarray:
    """The tracks log's rows, one per frame (the log samples every probe period: a frame's row
    repeats until the next frame's), the empty rows before the first frame left out."""
    rows = np.asarray(series["tracks"])
    rows = rows[np.any(rows[:, 1:] != 0, axis=1)]
    return rows[np.r_[True, np.diff(rows[:, 0]) != 0]] if len(rows) else rows


def confirmed_tracks(series: dict) -> list[TrackPath]:
    """The confirmed tracks of the run's tracks log (module docstring), by id."""
    if "tracks" not in series:
        return []
    hits: dict = {}
    paths: dict = {}
    for row in _frames(series):
        for slot in row[1:].reshape(MAX_TRACKS, ROW):
            track = int(slot[0])
            if track == 0:
                continue
            hits[track] = hits.get(track, 0) + int(slot[2] > 0.5)
            if hits[track] >= CONFIRM:
                paths.setdefault(track, []).append((row[0], slot[3:6].copy(), int(slot[6])))
    return [TrackPath(k, rows[-1][2], np.array([r[0] for r in rows]), np.array([r[1] for r in rows]))
            for k, rows in sorted(paths.items())]


def track_rgba(index: int) -> tuple:
    """The ``index``-th track's colour (RGBA)."""
    return (*TRACK_RGB[index % len(TRACK_RGB)], 1.0)


def draw_track_markers(meshcat, tracks: list[TrackPath]) -> list[str]:
    """Each track's sphere at ``tracks/track_{id}``, hidden (``track_poses`` shows and moves it);
    returns their paths."""
    from pydrake.geometry import Rgba, Sphere  # noqa: PLC0415

    paths = []
    for index, track in enumerate(tracks):
        path = f"tracks/track_{track.id}"
        meshcat.SetObject(path, Sphere(MARK_RADIUS), Rgba(*track_rgba(index)))
        meshcat.SetProperty(path, "visible", False)
        paths.append(path)
    return paths


def class_heights(scenario) -> list[float]:
    """Per class of the catalog (``part_tracks.catalog``) its height (m): a box's size z, a
    cylinder's length."""
    from ptint_drake.worlds.pick.part_tracks import catalog  # noqa: PLC0415

    return [part_height(shape, size) for shape, size in catalog(scenario.pick)[0]]


def track_poses(tracks: list[TrackPath], heights: list[float], t: float) -> list[tuple]:
    """(path, shown, position) of each track's sphere at replay time ``t``: shown from its
    confirmation to its last frame in the log, at its latest centre then (over its part's top)."""
    out = []
    for track in tracks:
        k = int(np.searchsorted(track.times, t + 1e-9, side="right")) - 1
        shown = k >= 0 and t <= track.times[-1] + 1e-9
        centre = track.centres[max(k, 0)].copy()
        centre[2] += 0.5 * heights[min(track.kind, len(heights) - 1)] + MARK_ABOVE
        out.append((f"tracks/track_{track.id}", bool(shown), centre))
    return out
