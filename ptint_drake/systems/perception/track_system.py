"""``TrackingPartPoseEstimator`` — the perception of many parts (issue 44): ``PartPoseEstimator``
whose fits go to the declared parts through ``tracks.Tracker`` (one track per part seen, gated
assignment, births, coasting through occlusions, ends, classes, binding by class and arrival
order) instead of "the nearest to its last fit, or — never seen — the farthest downstream".

Per frame (its periodic update), the good fits of the frame (``fit_catalog`` classes them when
the catalog has several kinds) are the tracker's detections; declared part i is given the fit
its bound track took this frame (none: a dropout, as before).  The tracker's state is discrete
state (the pick world's re-plans carry it).  Output ``tracks`` (1 + ``MAX_TRACKS`` × 7): [the
frame's stamp, then per track slot: id (0: free), bound part (−1: none), 1 when it took a fit
this frame, that fit's centre (3; else the track's predicted one) and its class] — what the
metrics match against the truth for the identity switches (``worlds.pick.track_metrics``) — and
``tracker_state``: the whole tracker (``tracks.Tracker.state_vector``: every track's filter), what
a line's controller side reads (``worlds.pick.line.seen``).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.systems.perception.part_pose_estimator import PartPoseEstimator, PerceptionConfig
from ptint_drake.systems.perception.tracks import MAX_TRACKS, Detection, Track, Tracker

ROW = 7  # per track slot in ``tracks``: id, bound part, took a fit, x, y, z, class


class TrackingPartPoseEstimator(PartPoseEstimator):
    """``PartPoseEstimator`` associating by tracks (module docstring); ``config.tracking``: the
    ``tracks.TrackerSettings`` (its ``objects``: the declared parts, as ``object_belts``)."""

    def __init__(self, config: PerceptionConfig):
        super().__init__(config)
        self._settings = config.tracking
        initial = Tracker(self._settings).state_vector()
        self._track_state = self.DeclareDiscreteState(initial)
        self._frame = self.DeclareDiscreteState(np.zeros(1 + MAX_TRACKS * ROW))
        self.DeclareVectorOutputPort("tracks", 1 + MAX_TRACKS * ROW, self._tracks_calc,
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclareVectorOutputPort("tracker_state", len(initial), self._tracker_state_calc,
                                     prerequisites_of_calc={self.xd_ticket()})

    def tracker(self, context) -> Tracker:
        """The tracker as of ``context`` (its tracks: ``Tracker.tracks``)."""
        return Tracker(self._settings).load(context.get_discrete_state(self._track_state).value())

    def live_tracks(self, context) -> list[Track]:
        """The confirmed and tentative tracks as of ``context``."""
        return self.tracker(context).tracks

    def _tracks_calc(self, context, output) -> None:
        output.SetFromVector(context.get_discrete_state(self._frame).value())

    def _tracker_state_calc(self, context, output) -> None:
        output.SetFromVector(context.get_discrete_state(self._track_state).value())

    def _choose(self, context, state, t: float, fits: list, memory: np.ndarray) -> list:
        """The tracker's step at the frame's time ``t`` (a fit made elsewhere is written later:
        ``frame_process``), then per object the fit of its bound track, or None."""
        tracker = self.tracker(context)
        good = [f for f in fits if f.ok]
        assigned = tracker.step(t, [Detection(f.position, f.yaw, f.kind, f.belt) for f in good])
        chosen = []
        for i in range(len(self._c.object_belts)):
            track = tracker.of_object(i)
            chosen.append(good[assigned[track.id]] if track is not None and track.id in assigned else None)
        frame = np.zeros((MAX_TRACKS, ROW))
        for row, track in zip(frame, tracker.tracks):
            j = assigned.get(track.id)
            where = good[j].position if j is not None else [track.x[0], track.x[1], track.z]
            row[:] = [track.id, track.object, float(j is not None), *where, track.kind]
        state.get_mutable_discrete_state(self._track_state).SetFromVector(tracker.state_vector())
        state.get_mutable_discrete_state(self._frame).SetFromVector(np.concatenate([[t], frame.ravel()]))
        return chosen
