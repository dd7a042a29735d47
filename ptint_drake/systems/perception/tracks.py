"""Multi-part tracking (issue 44): one track per part seen on the belts, from the fits of each
frame — pure numpy/scipy, no Drake (``track_system`` puts it in the perception's loop).

``Tracker.step(t, detections)`` per frame:

1. predict every live track to t (its own constant-velocity Kalman filter in the horizontal
   plane, white acceleration ``ACCEL_STD``);
2. gate: a detection may go to a track only within ``gate`` of its predicted centre —
   ``GATE_MIN`` plus three predicted standard deviations, at most ``GATE_MAX`` (less than half
   the closest centre distance of two 30 mm cubes 60 mm apart, and more than a coasted part's
   drift over an occlusion);
3. assign: ``scipy.optimize.linear_sum_assignment`` over the gated distances (a detection of
   another class than a confirmed track's costs ``CLASS_PENALTY`` more);
4. update the assigned tracks (position, height, yaw unwrapped by the class's symmetry: a cube's
   yaw modulo 90°, another box's modulo 180°, a cylinder's none; the class votes);
5. coast the others on their filters: a tentative track with ``TENTATIVE_MISSES`` misses is
   dropped; a confirmed one ends when its predicted centre leaves the view (``visible``) or it
   went unseen for ``MAX_COAST`` (held through the arm's occlusion, ended once picked);
6. birth: each detection left over starts a tentative track (velocity prior: its belt's
   configured velocity), confirmed after ``CONFIRM`` hits;
7. binding: a newly confirmed track (most downstream first) is bound to the first declared part
   (``objects``: class and belt) not yet bound, in arrival order (``arrival``) — the task's part
   is "the k-th part of its class to arrive on its belt".  A part that is hidden when it arrives
   and confirmed after one behind it takes the later slot of that order.

The whole state is a flat vector (``state_vector`` / ``from_vector``): Drake's discrete state
carries it across the pick world's re-plans, which copy the numeric state only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from scipy.optimize import linear_sum_assignment

GATE_MIN = 0.008  # m
GATE_MAX = 0.025  # m
CLASS_PENALTY = 0.02  # m, added to a confirmed track's distance to a detection of another class
BIG = 1.0e6
CONFIRM = 3  # hits
TENTATIVE_MISSES = 2  # frames in a row
MAX_COAST = 2.5  # s unseen (a part hidden by the arm for ~1 s before its grasp is held)
MEAS_STD = 0.001  # m, a fit's horizontal noise as the track filters assume it
ACCEL_STD = 0.05  # m/s², white acceleration of a part on a belt
VELOCITY_STD = 0.05  # m/s, a new track's velocity about its belt's configured velocity
MAX_TRACKS = 16
FREE, TENTATIVE, CONFIRMED = 0, 1, 2
# per row: id, status, belt, object, hits, misses, born, last seen, last predicted, x (4), P (16), z, yaw
_BASE = 31


@dataclass
class Detection:
    """One good fit of a frame: centre (m, world), yaw (rad), class (index in the catalog), belt."""

    position: np.ndarray
    yaw: float
    kind: int
    belt: int


@dataclass
class TrackerSettings:
    """What the tracker knows: per class its yaw symmetry (rad, 0: none), per belt a configured
    velocity (m/s, 3; zeros: unknown), the declared parts (class, belt) and their arrival order
    (indices into ``objects``), and which points the camera sees (None: all)."""

    symmetries: list
    belt_velocities: list
    objects: list = field(default_factory=list)
    arrival: list = field(default_factory=list)
    visible: Optional[Callable[[np.ndarray], bool]] = None


@dataclass
class Track:
    """One track: ``id`` (1, 2, … never reused), ``status``, its ``belt``, the declared part it is
    bound to (``object``, −1: none), hits, frames missed in a row, when it was born, last seen
    and last predicted, its filter (x = [px, py, vx, vy], P), height and unwrapped yaw, and per
    class its votes."""

    id: int
    status: int
    belt: int
    object: int
    hits: int
    misses: int
    born: float
    seen: float
    t: float
    x: np.ndarray
    P: np.ndarray
    z: float
    yaw: float
    votes: np.ndarray

    @property
    def kind(self) -> int:
        """The class most of its fits had (the first of equal counts)."""
        return int(np.argmax(self.votes))


class Tracker:
    """The tracks of all parts seen (module docstring)."""

    def __init__(self, settings: TrackerSettings):
        self.s = settings
        self.classes = len(settings.symmetries)
        self.tracks: list[Track] = []
        self.next_id = 1
        self.bound = [0] * len(settings.objects)  # per declared part: its track's id (0: none yet)

    # --- state as a vector (Drake's discrete state) ---------------------------------------------
    def width(self) -> int:
        """Numbers per track row."""
        return _BASE + self.classes

    def size(self) -> int:
        """Length of ``state_vector``."""
        return 1 + len(self.s.objects) + MAX_TRACKS * self.width()

    def state_vector(self) -> np.ndarray:
        """[next id, bound ids (per object), track rows (``MAX_TRACKS``; status 0: free)]."""
        rows = np.zeros((MAX_TRACKS, self.width()))
        for r, tr in zip(rows, self.tracks[:MAX_TRACKS]):
            r[:9] = [tr.id, tr.status, tr.belt, tr.object, tr.hits, tr.misses, tr.born, tr.seen, tr.t]
            r[9:13], r[13:29], r[29], r[30] = tr.x, tr.P.ravel(), tr.z, tr.yaw
            r[_BASE:] = tr.votes
        return np.concatenate([[self.next_id], self.bound, rows.ravel()])

    def load(self, vector) -> "Tracker":
        """Set the state from ``state_vector``'s layout; returns self."""
        v = np.asarray(vector, float)
        n = len(self.s.objects)
        self.next_id, self.bound = int(v[0]), [int(b) for b in v[1:1 + n]]
        self.tracks = []
        for r in v[1 + n:].reshape(MAX_TRACKS, self.width()):
            if int(r[1]) == FREE:
                continue
            self.tracks.append(Track(int(r[0]), int(r[1]), int(r[2]), int(r[3]), int(r[4]), int(r[5]),
                                     float(r[6]), float(r[7]), float(r[8]), r[9:13].copy(),
                                     r[13:29].reshape(4, 4).copy(), float(r[29]), float(r[30]),
                                     r[_BASE:].copy()))
        return self

    # --- one frame ------------------------------------------------------------------------------
    def step(self, t: float, detections: list[Detection]) -> dict[int, int]:
        """Process one frame at ``t``; returns {track id: index of its detection} of this frame."""
        for tr in self.tracks:
            self._predict(tr, t)
        pairs = self._assign(detections)
        for k, j in pairs.items():
            self._update(self.tracks[k], t, detections[j])
        assigned = {self.tracks[k].id: j for k, j in pairs.items()}
        for k, tr in enumerate(self.tracks):
            if k not in pairs:
                tr.misses += 1
        self.tracks = [tr for tr in self.tracks if not self._ended(tr, t)]
        taken = set(pairs.values())
        for j, d in enumerate(detections):
            if j not in taken and len(self.tracks) < MAX_TRACKS:
                self.tracks.append(self._born(t, d))
                assigned[self.tracks[-1].id] = j
        self._confirm()
        return assigned

    def _predict(self, tr: Track, t: float) -> None:
        dt = t - tr.t
        if dt <= 0.0:
            return
        F = np.eye(4)
        F[0, 2] = F[1, 3] = dt
        g = np.array([[0.5 * dt * dt, 0.0], [0.0, 0.5 * dt * dt], [dt, 0.0], [0.0, dt]])
        tr.x = F @ tr.x
        tr.P = F @ tr.P @ F.T + ACCEL_STD ** 2 * g @ g.T
        tr.t = t

    def gate(self, tr: Track) -> float:
        """m: how far from its predicted centre a detection may be to go to ``tr``."""
        sigma = math.sqrt(max(float(np.linalg.eigvalsh(tr.P[0:2, 0:2])[-1]), 0.0))
        return min(GATE_MIN + 3.0 * sigma, GATE_MAX)

    def _assign(self, detections: list[Detection]) -> dict[int, int]:
        """{track index: detection index} of the gated optimal assignment."""
        if not self.tracks or not detections:
            return {}
        cost = np.full((len(self.tracks), len(detections)), BIG)
        for k, tr in enumerate(self.tracks):
            g = self.gate(tr)
            for j, d in enumerate(detections):
                dist = float(np.hypot(*(np.asarray(d.position)[0:2] - tr.x[0:2])))
                if dist <= g:
                    wrong = tr.status == CONFIRMED and d.kind != tr.kind
                    cost[k, j] = dist + (CLASS_PENALTY if wrong else 0.0)
        rows, cols = linear_sum_assignment(cost)
        return {int(k): int(j) for k, j in zip(rows, cols) if cost[k, j] < BIG}

    def _update(self, tr: Track, t: float, d: Detection) -> None:
        H = np.zeros((2, 4))
        H[0, 0] = H[1, 1] = 1.0
        S = H @ tr.P @ H.T + MEAS_STD ** 2 * np.eye(2)
        K = tr.P @ H.T @ np.linalg.inv(S)
        tr.x = tr.x + K @ (np.asarray(d.position)[0:2] - tr.x[0:2])
        tr.P = (np.eye(4) - K @ H) @ tr.P
        tr.z += (float(d.position[2]) - tr.z) / (tr.hits + 1)
        tr.votes[d.kind] += 1.0
        step = self.s.symmetries[tr.kind]
        tr.yaw = tr.yaw + ((d.yaw - tr.yaw + 0.5 * step) % step - 0.5 * step) if step > 0.0 else 0.0
        tr.hits, tr.misses, tr.seen = tr.hits + 1, 0, t

    def _ended(self, tr: Track, t: float) -> bool:
        if tr.misses == 0:
            return False
        if tr.status == TENTATIVE:
            return tr.misses >= TENTATIVE_MISSES
        gone = self.s.visible is not None and not self.s.visible(np.array([tr.x[0], tr.x[1], tr.z]))
        return gone or t - tr.seen > MAX_COAST

    def _born(self, t: float, d: Detection) -> Track:
        v = np.asarray(self.s.belt_velocities[d.belt], float)[0:2] if self.s.belt_velocities else np.zeros(2)
        votes = np.zeros(self.classes)
        votes[d.kind] = 1.0
        step = self.s.symmetries[d.kind]
        tr = Track(self.next_id, TENTATIVE, d.belt, -1, 1, 0, t, t, t,
                   np.array([d.position[0], d.position[1], v[0], v[1]], float),
                   np.diag([MEAS_STD ** 2, MEAS_STD ** 2, VELOCITY_STD ** 2, VELOCITY_STD ** 2]),
                   float(d.position[2]), float(d.yaw) if step > 0.0 else 0.0, votes)
        self.next_id += 1
        return tr

    def _confirm(self) -> None:
        """Tentative tracks with ``CONFIRM`` hits become confirmed and are bound (module docstring)."""
        new = [tr for tr in self.tracks if tr.status == TENTATIVE and tr.hits >= CONFIRM]

        def downstream(tr: Track) -> float:
            v = np.asarray(self.s.belt_velocities[tr.belt], float)[0:2] if self.s.belt_velocities else 0.0
            return float(np.dot(tr.x[0:2], v))

        for tr in sorted(new, key=lambda tr: (tr.born, -downstream(tr))):
            tr.status = CONFIRMED
            for i in self.s.arrival:
                kind, belt = self.s.objects[i]
                if self.bound[i] == 0 and kind == tr.kind and belt == tr.belt:
                    self.bound[i], tr.object = tr.id, i
                    break

    def of_object(self, i: int) -> Optional[Track]:
        """The live track bound to declared part ``i`` (None: not yet bound, or ended)."""
        return next((tr for tr in self.tracks if tr.id == self.bound[i] and self.bound[i]), None)


def identity_switches(matches) -> dict:
    """The identity switches (IDSW of CLEAR-MOT) of a run: ``matches`` is, frame after frame, a
    list of (true part, track id) — which part each track's fit of that frame came from (the
    truth's side: the nearest simulated part).  A switch is a part whose fit goes to another
    track than the one it last went to (a track lost and born anew, or two tracks trading
    parts).  Returns {``idsw``, ``tracks_per_part`` (per part: the ids in order of use),
    ``parts_per_track`` (per track id: the parts it took fits of)}."""
    last: dict = {}
    per_part: dict = {}
    per_track: dict = {}
    switches = 0
    for frame in matches:
        for part, track in frame:
            if part in last and last[part] != track:
                switches += 1
            last[part] = track
            ids = per_part.setdefault(part, [])
            if not ids or ids[-1] != track:
                ids.append(track)
            owners = per_track.setdefault(track, [])
            if part not in owners:
                owners.append(part)
    return {"idsw": switches, "tracks_per_part": per_part, "parts_per_track": per_track}
