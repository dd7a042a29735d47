"""An outgoing belt as a line's destination (issue 44: "where each kind of part goes — tray slots,
a bin, or an outgoing belt"): where on it a part is put, the cycle of a place riding it, and what
counts as put on it.

A catalog kind with ``belt`` (``config.line.KindConfig``) is put on that belt of ``pick.belts``.
The place is a target riding the belt at its speed as the controller side knows it (its declared
speed: the outgoing belt has no track to learn it from; ``tasks.place_ride``): the carry aims
``lift_height`` above the place point as it rides, the place at the point itself, the retreat
``clearance`` above it, still riding (``tasks``, ``targets.PickTargets``).  The part's closing
axis lies across the belt (``tasks.place_target``), so the open fingers stand beside the part
across the belt and never reach towards the parts before and after it.

Choices the issue leaves open, made here:

- **The place point** (``OutPlaces.choose``): on the belt's centre line, in belt coordinates at
  t = 0 (``PickTaskConfig.belt_at``: the point rides on with the belt).  Preferred: the point of
  the centre line nearest the grasp point (the shortest carry), clipped so that the carry's
  target, the place and the retreat stay inside the arm's reach window on that belt
  (``LineView.window_at``: the same Drake IK from above, at the point and ``lift_height`` above,
  that gives the grasp's window).  Of the points that keep a pitch from every part already put on
  the belt (every task committed to it, a failed one too) and lie in the window, the one nearest
  the preferred (``free_point``: the preferred itself, a window's end, or a pitch from a part).
- **The pitch** (``pitch``), centre to centre along the belt: half the longer of the new part's
  length along the belt and the open fingers' width (``grasp_gate.finger_extent``), half the
  placed part's length, and ``PLACE_GAP`` = 10 mm (the place's error, a few mm measured, and the
  part's settling as the fingers open).
- **Put on the belt** (``on_belt``; no mm criterion to a point, as for a bin): judged from the
  truth at the retreat's end (the part released at its planned time, the hand risen): the part's
  centre ``h/2`` above the belt's top within ``REST_TOL`` (resting on it), its footprint inside
  the belt's width, tilted at most ``UPRIGHT_DEG`` (upright).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.config.part_shape import footprint_radius, part_height
from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.phase_time import NoTfFits
from ptint_drake.worlds.pick.scene import belt_frame

PLACE_GAP = 0.010  # m, between the open fingers (or the part) and the part put before it
REST_TOL = 0.003  # m: the centre's height above the belt's top off h/2 that still rests on it
UPRIGHT_DEG = 10.0  # deg: the most a part put on the belt may be tilted
PASSES = 3  # the place point and the cycle found again from each other


@dataclass(frozen=True)
class OutPlace:
    """A decision's destination on outgoing belt ``belt``: ``along`` (m, belt coordinate at
    t = 0; None: not chosen yet)."""

    belt: str
    along: Optional[float] = None

    def fields(self) -> dict:
        """The task's place fields (``PickTaskConfig``)."""
        return {"belt": self.belt, "belt_at": float(self.along or 0.0), "slot": None, "bin": ""}


def length_along(part) -> float:
    """m: a part's length along the belt, its closing axis across it (box: its y size)."""
    return float(part.size[1] if part.shape == "box" else part.size[0])


def pitch(part, placed, finger_width: float) -> float:
    """m, centre to centre, between ``part`` and ``placed`` on the belt (module docstring)."""
    return 0.5 * max(length_along(part), finger_width) + 0.5 * length_along(placed) + PLACE_GAP


def ride_of(belt) -> np.ndarray:
    """m/s (world): belt's declared velocity."""
    d = np.asarray(belt.direction, dtype=float)
    return belt.speed * d / np.linalg.norm(d)


def placed_on(tasks: list, belt: str, parts: dict, skip: Optional[int] = None) -> list:
    """[(belt_at, part)] of every task (but ``skip``) put on ``belt``; ``parts``: name → PartConfig."""
    return [(t.belt_at, parts[t.part]) for k, t in enumerate(tasks) if t.belt == belt and k != skip]


def free_point(preferred: float, lo: float, hi: float, part, placed: list, finger_width: float):
    """The belt coordinate (t = 0) nearest ``preferred`` in [lo, hi] at least a pitch from every
    ``placed`` (belt_at, part) (module docstring); None where there is none."""
    gaps = [(a, pitch(part, p, finger_width)) for a, p in placed]
    # the free set is [lo, hi] less an open stretch a pitch either side of each part: the nearest
    # free point is the preferred one or an end of a stretch or of the window
    candidates = [preferred, lo, hi] + [a + s * g for a, g in gaps for s in (-1.0, 1.0)]
    ok = [c for c in candidates if lo - 1e-9 <= c <= hi + 1e-9
          and all(abs(c - a) >= g - 1e-9 for a, g in gaps)]
    return min(ok, key=lambda c: abs(c - preferred)) if ok else None


def choose(pick, belt_name: str, window: tuple, grasp: float, cycle_of, part, placed: list,
           finger_width: float, grasp_point) -> tuple:
    """(``OutPlace`` with its point, its ``Cycle``) of a part grasped at ``grasp`` (s) at
    ``grasp_point`` and put on ``belt_name`` (module docstring); ``window``: its reach window
    [s_in, s_out] (m along the belt); ``cycle_of(along)``: the cycle to that point.  ``NoTfFits``
    naming why where no point fits."""
    index = [b.name for b in pick.belts].index(belt_name)
    belt = pick.belts[index]
    v = float(np.linalg.norm(ride_of(belt)))
    local = belt_frame(belt).inverse().multiply(np.asarray(grasp_point, dtype=float))
    along, cycle = None, None
    dwell = PickTaskConfig().dwell
    for _ in range(PASSES):
        tf = cycle.phases if cycle is not None else dict.fromkeys(("lift", "carry", "place", "retreat"), 0.0)
        t_place = grasp + dwell + tf["lift"] + tf["carry"] + tf["place"]
        before, after = v * (tf["carry"] + tf["place"]), v * (dwell + tf["retreat"])
        lo, hi = window[0] + before - v * t_place, window[1] - after - v * t_place
        preferred = float(np.clip(local[0] - v * t_place, lo, hi)) if lo <= hi else lo
        found = free_point(preferred, lo, hi, part, placed, finger_width) if lo <= hi else None
        if found is None:
            raise NoTfFits(f"no free point on belt {belt_name!r} in reach at the place time {t_place:.2f} s "
                           f"(pitch, reach window {window[0]:.3f} … {window[1]:.3f} m)")
        if along is not None and abs(found - along) < 1e-4:
            return OutPlace(belt_name, along), cycle
        along = found
        cycle = cycle_of(along)
    return OutPlace(belt_name, along), cycle


def across_yaw(belt, near: float) -> float:
    """rad: the yaw that turns a part's closing axis across ``belt``, the branch nearest ``near``."""
    d = np.asarray(belt.direction, dtype=float)
    across = float(np.arctan2(d[1], d[0])) + 0.5 * np.pi
    return across + np.pi * round((near - across) / np.pi)


def place_of(pick, belt_name: str, part, along: float) -> np.ndarray:
    """The part's centre put on ``belt_name`` at ``along`` (t = 0), world (``cell.place_point``)."""
    return place_point(pick, "belt", [b.name for b in pick.belts].index(belt_name), part, along)


def on_belt(belt, p, R, part) -> bool:
    """Whether a part at ``p`` (world, m) turned ``R`` (3 × 3) rests upright on ``belt`` inside its
    width at its present position along it (module docstring)."""
    local = belt_frame(belt).inverse().multiply(np.asarray(p, dtype=float))
    height = part_height(part.shape, part.size)
    tilt = float(np.degrees(np.arccos(np.clip(np.asarray(R)[2, 2], -1.0, 1.0))))
    across = footprint_radius(part.shape, part.size)
    return bool(abs(local[2] - height / 2) <= REST_TOL and abs(local[1]) + across <= belt.width / 2 + 1e-9
                and abs(local[0]) <= belt.length / 2 and tilt <= UPRIGHT_DEG)
