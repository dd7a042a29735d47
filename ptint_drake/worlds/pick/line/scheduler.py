"""The line's online scheduler: which part the free arm picks next, and when — a pure function
over what the controller side knows (tracks, the known belt speeds, the reach windows, its own
assignments and the slots it has filled, the time), with every skip named.

``decide`` looks at each confirmed, unassigned track (``Track``: a part the sensor reports on a
belt, moving at the belt's *known* velocity — the encoder's reading, or the declared speed) and
finds its grasp time on a grid of ``Timing.step`` from the decision:

1. a free slot of its kind (a bin never fills), else ``tray full``;
2. its reach window (``windows[id]`` = [s_in, s_out]: where along its belt a top-down grasp and
   the lift above it are reachable, found by Drake's IK, ``robot.reachability``) — the predicted
   coordinate s(t) = s + speed · (t − now) inside it at the grasp time;
3. the earliest grasp time at least the track's lead after now or, if later, after the part
   enters its window (``leads``: the phase time model's, ``line.cycle``: its approach from the
   arm's present point ends as the part enters, every sample of its way checked by IK, then the
   descend; without it ``Timing.lead``, the tasks' default tfs, the whole approach with the part
   in reach — a prescribed-time approach aims at the moving part all along, and unchecked, a
   grasp at the window's entry ran the RV-M1 through its base into its joint limits), and at least
   ``Timing.slack`` before the part leaves it (so that the lift too is done in reach): else
   ``not reachable in time`` when the window closes too soon, or ``not in reach yet`` when the
   part is still upstream beyond the look-ahead ``Timing.horizon`` (not a failure: looked at again);
4. finger clearance at that time from every other track predicted to it (``grasp_gate``'s rule:
   ``finger_clearance`` < ``FINGER_MARGIN``: ``blocked``).

Of the candidates left, the one whose window closes first (earliest deadline first), ties by the
lower id.  ``Decision.skipped`` holds every other track with its reason (the chosen one's
rivals that were feasible read ``later deadline``, their deadlines in ``rivals``).

``drifted``: the known prediction of a committed grasp point against the one the decision made:
beyond the tolerance, the run decides again (``driver``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Optional

import numpy as np

from ptint_drake.worlds.pick.grasp_gate import FINGER_MARGIN, finger_clearance


@dataclass(frozen=True)
class Track:
    """A part as the controller side knows it: its ``id`` (the sensor's), ``kind``, ``belt``,
    position (world, m), s: its coordinate along its belt (m), the belt's direction and known
    ``speed`` (m/s), its ``axis`` (the x axis the fingers close along, world), its ``width``
    across the fingers, its top face's ``radius`` (m, any yaw) and the ``measured`` speed along
    the belt the sensor reports for it (m/s; what a drift is checked again with)."""

    id: int
    kind: str
    belt: str
    position: tuple
    s: float
    direction: tuple
    speed: float
    axis: tuple
    width: float
    radius: float
    measured: float = math.nan  # m/s along the belt: the sensor's own velocity of the part (if any)

    def at(self, t: float, now: float) -> np.ndarray:
        """The predicted position at ``t`` (the known belt velocity)."""
        return np.asarray(self.position) + self.speed * (t - now) * np.asarray(self.direction)


@dataclass(frozen=True)
class Timing:
    """The grasp-time search: ``lead`` (s, the least time to a grasp), ``step`` (s, the grid),
    ``horizon`` (s, the look-ahead), ``slack`` (s, the least time left in reach after the grasp),
    ``margin`` (m, the open fingers' clearance around a part), ``finger`` ((thickness, width), m)."""

    lead: float
    step: float = 0.1
    horizon: float = 10.0
    slack: float = 0.5
    margin: float = 0.012
    finger: tuple = (0.006, 0.02)


@dataclass
class Decision:
    """At ``t``: the chosen track, its grasp time, slot and deadline (None: nothing chosen), and
    every skipped track with its reason [(id, reason)]."""

    t: float
    track: Optional[int] = None
    grasp: Optional[float] = None
    slot: Optional[int | str] = None  # a tray slot, or the name of the kind's bin
    deadline: Optional[float] = None
    point: Optional[tuple] = None
    skipped: list = field(default_factory=list)
    rivals: dict = field(default_factory=dict)  # id → the deadline of a feasible track not chosen

    def record(self) -> dict:
        """The decision log's entry (metrics.json ``line.decisions``)."""
        return {"t": round(self.t, 4), "track": self.track,
                "grasp": None if self.grasp is None else round(self.grasp, 4),
                "slot": self.slot.fields() if hasattr(self.slot, "fields") else self.slot,  # (outbelt46)
                "deadline": None if self.deadline is None else round(self.deadline, 4),
                "skipped": [{"track": i, "reason": r} | ({"deadline": round(self.rivals[i], 4)}
                                                          if i in self.rivals else {})
                            for i, r in self.skipped]}


def grasp_time(track: Track, window: tuple, now: float, timing: Timing, lead: Optional[float] = None):
    """(grasp time, deadline) of ``track`` in its reach ``window`` (module docstring, step 3), or
    (None, reason); ``lead``: this track's (s, the model's approach and descend), else
    ``timing.lead``."""
    s_in, s_out = window
    lead = timing.lead if lead is None else lead
    if track.speed <= 1e-9:
        inside = s_in <= track.s <= s_out
        return (now + lead, math.inf) if inside else (None, "not in reach (belt stopped)")
    leave = now + (s_out - track.s) / track.speed  # the part's centre leaves the window
    enter = now + (s_in - track.s) / track.speed
    deadline = leave - timing.slack
    if enter - now > timing.horizon:
        return None, "not in reach yet"
    earliest = max(now, enter) + lead  # in reach from the approach's start on
    t = now + timing.step * math.ceil((earliest - now) / timing.step - 1e-9)
    if t > deadline:
        return None, "not reachable in time"
    return t, deadline


def blocker(track: Track, tracks: list, grasp: float, now: float, timing: Timing) -> Optional[int]:
    """The id of a track whose part the open fingers of a grasp of ``track`` at ``grasp`` would
    hit (grasp_gate's rule), or None."""
    centre = track.at(grasp, now)
    opening = track.width + timing.margin
    for other in tracks:
        if other.id == track.id:
            continue
        gap = finger_clearance(centre, track.axis, opening, timing.finger, other.at(grasp, now), other.radius)
        if gap < FINGER_MARGIN:
            return other.id
    return None


def decide(now: float, tracks: list, windows: dict, assigned: set, free_slots: dict,
           timing: Timing, leads=None, axes=None) -> Decision:
    """The next pick among ``tracks`` not in ``assigned`` (module docstring); ``free_slots``: kind
    → the slots still free for it, in filling order (a bin kind: [its bin's name]); ``leads``: a
    callable (track, window) → the track's lead (s, ``line.cycle.LineCycles.lead``: the min-tf
    model) or a str naming why no tf fits — None: ``timing.lead`` for every track.  A deadline does
    not depend on the lead, so the tracks are looked at in deadline order, and with ``leads`` the
    model is asked no further than the first feasible one (the rest read ``later deadline``);
    ``axes``: a callable track → the fingers' closing axis at its grasp (the grip the lead chose,
    ``LineCycles.axis``; None: ``Track.axis``)."""
    decision = Decision(now)
    order = []
    for track in tracks:
        if track.id in assigned:
            continue
        if not free_slots.get(track.kind):
            decision.skipped.append((track.id, "tray full"))
            continue
        grasp, deadline = grasp_time(track, windows[track.id], now, timing, 0.0)  # no lead: none fits
        if grasp is None:
            decision.skipped.append((track.id, deadline))
            continue
        order.append((deadline, track.id, track))
    order.sort(key=lambda f: f[:2])
    feasible = []
    for deadline, _, track in order:
        if feasible and leads is not None:
            feasible.append((deadline, None, track))
            continue
        reason, grasp = _feasible(track, tracks, windows[track.id], now, timing, leads, axes)
        if reason:
            decision.skipped.append((track.id, reason))
        else:
            feasible.append((deadline, grasp, track))
    if not feasible:
        return decision
    deadline, grasp, chosen = feasible[0]
    decision.skipped += [(f[2].id, "later deadline") for f in feasible[1:]]
    decision.rivals = {f[2].id: f[0] for f in feasible[1:]}
    decision.track, decision.grasp, decision.deadline = chosen.id, grasp, deadline
    decision.slot = free_slots[chosen.kind][0]
    decision.point = tuple(float(c) for c in chosen.at(grasp, now))
    return decision


def _feasible(track: Track, tracks: list, window: tuple, now: float, timing: Timing, leads,
              axes=None) -> tuple:
    """("", grasp time) of a track the arm can take (its lead, its grasp time in its window, the
    fingers clear of the others), else (the reason, None)."""
    lead = None if leads is None else leads(track, window)
    if isinstance(lead, str):
        return lead, None
    grasp, deadline = grasp_time(track, window, now, timing, lead)
    if grasp is None:
        return deadline, None
    gripped = track if axes is None else replace(track, axis=tuple(axes(track)))
    hit = blocker(gripped, tracks, grasp, now, timing)
    return (f"blocked (track {hit})", None) if hit is not None else ("", grasp)


def drifted(track: Track, grasp: float, point: tuple, now: float, tolerance: float) -> float:
    """m by which the grasp point predicted now (the known velocity) is off the committed
    ``point``, if beyond ``tolerance`` (m); else 0."""
    off = float(np.linalg.norm(track.at(grasp, now) - np.asarray(point)))
    return off if off > tolerance else 0.0
