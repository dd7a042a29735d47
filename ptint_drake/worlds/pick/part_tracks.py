"""The pick world's parts as tracks (issue 44): what the perception is told of the declared parts
(configuration only), and the identity switches of a run against the truth.

``catalog`` — the kinds of part the scenario declares, (shape, size) each, in order of first
appearance, and each part's kind: the classes the perception fits every cluster against
(``systems.perception.catalog_fit``), so boxes and cylinders may be mixed.

``tracker_settings`` — ``tracks.TrackerSettings``: per class its yaw symmetry
(``part_fit.yaw_symmetry``), per perceived belt its configured velocity (the pick belt of the
parts found on it; zeros when none), the declared parts as (class, perceived belt) and their
arrival order — by their nominal place along their belt at t = 0, downstream first (parts on one
belt do not overtake each other) — and the camera's view (``rgbd_camera.in_view``: a track whose
predicted centre leaves it ends).  Task k's part is thus "the n-th part of its class to arrive on
its belt", whatever fit came first.

``track_metrics`` — metrics.json's ``tracking``: every frame's fits taken by a track (the
perception's ``tracks`` log) matched to the simulated part nearest each (within ``TRUTH_GATE``;
farther: ``false_fits``, a fit of no part), then ``tracks.identity_switches`` — ``idsw`` (must be
0), per part the ids of the tracks that took its fits, per track the parts it took fits of.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ptint_drake.config.pick import PickConfig
from ptint_drake.systems.perception.part_fit import yaw_symmetry
from ptint_drake.systems.perception.rgbd_camera import in_view
from ptint_drake.systems.perception.track_system import ROW
from ptint_drake.systems.perception.tracks import MAX_TRACKS, TrackerSettings, identity_switches

TRUTH_GATE = 0.02  # m, a fit farther than this from every simulated part is of none


def catalog(pick: PickConfig) -> tuple[list, list[int]]:
    """([(shape, size)] of the declared kinds, per part its kind's index) (module docstring)."""
    kinds, of = [], []
    for part in pick.parts:
        kind = (part.shape, [float(v) for v in part.size])
        if kind not in kinds:
            kinds.append(kind)
        of.append(kinds.index(kind))
    return kinds, of


@dataclass(frozen=True)
class CameraView:
    """Whether a point (world, m) is in the camera's view (``rgbd_camera.in_view``); an object,
    not a closure, so the settings pickle (the drive's perception process gets them)."""

    X_WC: object
    info: object

    def __call__(self, p) -> bool:
        return bool(in_view(self.X_WC, self.info, np.asarray(p, float)[None])[0])


def tracker_settings(pick: PickConfig, regions: list, part_belts: list[int], paths: list, X_WC,
                     info) -> TrackerSettings:
    """The tracker's settings (module docstring); ``part_belts``: per part its perceived belt;
    ``paths``: per part its nominal centre at t = 0 and its belt's velocity (``camera.nominal_paths``)."""
    kinds, kind_of = catalog(pick)
    velocities = [np.zeros(3) for _ in regions]
    for belt, (_, velocity) in zip(part_belts, paths):
        velocities[belt] = np.asarray(velocity, float)
    along = [float(np.dot(start, velocity)) for start, velocity in paths]
    arrival = sorted(range(len(pick.parts)), key=lambda k: -along[k])
    return TrackerSettings([yaw_symmetry(shape, size) for shape, size in kinds], velocities,
                           list(zip(kind_of, part_belts)), arrival,
                           visible=CameraView(X_WC, info))


def _frames(tracks_log: tuple):
    """(stamp, row) of each frame of the ``tracks`` log once (its first sample at or after the stamp)."""
    t, rows = tracks_log
    last = None
    for time, row in zip(t, rows):
        stamp = row[0]
        if stamp == last or time < stamp - 1e-9:
            continue
        last = stamp
        yield stamp, row


def frame_stamps(tracks_log: tuple) -> list[float]:
    """The stamps of ``frame_matches``' frames, in its order."""
    return [float(stamp) for stamp, _ in _frames(tracks_log)]


def frame_matches(tracks_log: tuple, truth: list[tuple]) -> tuple[list, int]:
    """Per frame of the ``tracks`` log (times, rows), [(part, track id)] of the fits taken, each
    matched to the nearest simulated part (``truth``: per part (times, poses) whose columns 0:3
    are its centre); and the count of fits no part is near."""
    frames, false_fits = [], 0
    for stamp, row in _frames(tracks_log):
        frame = []
        for slot in row[1:].reshape(MAX_TRACKS, ROW):
            if slot[0] == 0 or slot[2] < 0.5:
                continue
            distances = [np.linalg.norm(poses[min(np.searchsorted(times, stamp), len(times) - 1), 0:3]
                                        - slot[3:6]) for times, poses in truth]
            part = int(np.argmin(distances))
            if distances[part] > TRUTH_GATE:
                false_fits += 1
                continue
            frame.append((part, int(slot[0])))
        frames.append(frame)
    return frames, false_fits


def track_metrics(tracks_log: tuple, truth: list[tuple], names: list[str]) -> dict:
    """metrics.json's ``tracking`` (module docstring)."""
    frames, false_fits = frame_matches(tracks_log, truth)
    ids = identity_switches(frames)
    return {"idsw": ids["idsw"], "frames": len(frames), "false_fits": false_fits,
            "tracks_per_part": {names[p]: tracks for p, tracks in sorted(ids["tracks_per_part"].items())},
            "parts_per_track": {str(k): [names[p] for p in parts]
                                for k, parts in ids["parts_per_track"].items()}}
