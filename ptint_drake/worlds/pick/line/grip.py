"""The line's grasp and place yaws, chosen by the part's symmetry (issue 44).

The top-down tool grips a part across the faces its closing axis meets, and the controller's
task turns the tool to its target's yaw modulo π, on the branch nearest the tool's own yaw
(``orientation.top_down_of``).  A part that looks the same turned by its yaw symmetry
(``part_fit.yaw_symmetry``: a 30 mm cube π/2, another box π, a cylinder any yaw) can be gripped
across either pair of faces, or at any yaw, so the decision chooses (``grips``):

- a box with no symmetry below π: the part's yaw modulo π nearest the tool's (as before: one
  branch);
- a square-topped box: the part's yaw modulo π/2 nearest the tool's (a turn of at most 45°), then
  the other pair of faces (a turn of 45–90°) — where the first way has no top-down posture (the
  wrist's roll at its limit) the second may.  The other pair first where the nearer grip would
  turn a near quarter (``route.turn_ways``) to the slot's own yaw and the other would not, nor on
  its approach: the controller may take a near-quarter turn either way round, and the model then
  plans the slower (harsh line_assembly seed 11: the first cube, at the slot's yaw, gripped at 90°
  from the start posture's 112.5°, got a carry of 2.3 s planned both ways round; with no turn on
  it the same carry took 1.5 s);
- a cylinder: the tool's own yaw (no turn), then ±45°, then ±81° (``CYLINDER_TURNS``).

``line.cycle`` asks the min-tf model for each candidate in this order at each wait and keeps
the first that fits (``LineCycles._lead``); a grip whose cycle then finds no tf (the carry, the
place) is dropped for the track and the next look takes the next (``drop_grip``).  A grip whose
plan's via leg finds none is kept: such a leg fits a few looks later, the via moving with the part
(line_two_belts seed 1 at main: 10 looks, then the grasp at 24.4 s), and dropping it for the next
grip measured worse — seed 1's cube then grasped at 28.6 s on the other pair of faces, a later
part lost; seed 7's disc at 29.0 s, 2.8 s after main's, on its fifth grip.  The chosen yaw is the
task's ``grip_yaw`` for its whole life (``tasks.aimed_yaw``: the targets then follow the part's
estimated yaw by whole periods nearest it, so an estimate that moves by less than half a period
keeps the branch).

The place (``puts``): first the slot's own yaw modulo π nearest the grip — the tray's design
direction of the fingers, and the tool's yaw after each place kept where it was, so the wrist's
roll does not wander cycle after cycle — then, for a cube, the slot's yaw turned 90°, for a
cylinder the grip's yaw (no turn on the carry): each only where the open fingers there clear
every part already in the tray by ``grasp_gate.FINGER_MARGIN`` (``tray_clearance``: each finger a
rectangle, a placed box its rectangle at the yaw it was put at, a cylinder its disc).  On
line_two_belts' tray the slots are 50 mm apart in x and 40 mm in y: the open fingers reach 27 mm
from a 30 mm cube's centre, the neighbour's face is 35 mm away along x (8 mm clear) and 25 mm
across y — there they would touch, so a turned place is taken only where that neighbour is not
there yet.  The slot's own yaw is checked too (session 53: an iiwa line of 40 mm boxes in slots 50
mm apart along that side put the third box between two placed ones and pushed both 4 mm off);
a slot with no yaw left has no cycle (``line.slot_choice`` asks the next nearest).  A bin keeps
the yaw the part was gripped at (``tasks.place_target``).  ``LineCycles.phases`` keeps the first
candidate whose cycle fits.
"""

from __future__ import annotations

import math
from typing import Optional

import numpy as np

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.config import grasp_width
from ptint_drake.worlds.pick.grasp_gate import FINGER_MARGIN, finger_clearance
from ptint_drake.worlds.pick.route import nearest_branch, turn_ways
from ptint_drake.worlds.pick.tasks import aimed_yaw, part_symmetry, place_target

# rad: a cylinder's grips, turns from the tool's yaw (below 90°: the controller's branch, modulo π)
CYLINDER_TURNS = (0.0, -0.25 * math.pi, 0.25 * math.pi, -0.45 * math.pi, 0.45 * math.pi)


def grips(part, part_yaw: float, tool_yaw: float, place_yaw: Optional[float] = None) -> list:
    """rad: the grip yaws of ``part`` (a ``PartConfig``: its shape and size) at ``part_yaw`` for
    the tool at ``tool_yaw``, preferred first (module docstring), each within π/2 of ``tool_yaw``
    (the controller's branch); ``place_yaw``: the slot's yaw it goes to, if known (a square-topped
    box whose nearer grip would turn a near quarter to it is gripped across the other faces first)."""
    symmetry = part_symmetry(part)
    if symmetry <= 0.0:
        return [tool_yaw + turn for turn in CYLINDER_TURNS]
    if symmetry >= math.pi - 1e-9:
        return [nearest_branch(tool_yaw, part_yaw)]
    first = aimed_yaw(part_yaw, (tool_yaw, symmetry))
    second = nearest_branch(tool_yaw, first + symmetry)
    if place_yaw is not None and doubtful(first, nearest_branch(first, place_yaw)) \
            and not doubtful(second, nearest_branch(second, place_yaw)) and not doubtful(tool_yaw, second):
        return [second, first]
    return [first, second]


def slot_yaw(pick, kind: str) -> Optional[float]:
    """rad: the yaw of the first tray slot the catalog's ``kind`` goes to (``grips``' hint); None
    where it goes to a bin or an outgoing belt."""
    slots = pick.line.kind(kind).slots
    return place_target(pick, PickTaskConfig(slot=slots[0]))[2] if slots else None


def doubtful(start: float, end: float) -> bool:
    """Whether the top-down task may turn the tool from yaw ``start`` to the branch ``end`` (rad)
    either way round (``route.turn_ways``: a near-quarter turn)."""
    return len(turn_ways((start, end))) > 1


class Grips:
    """The grip yaws of a line's tracks (``grips``), less those dropped for a track (``drop``)."""

    def __init__(self):
        self.dropped: dict = {}  # track id → the grip yaws (rad, rounded) its cycle or plan found no tf for

    def of(self, track_id: int, part, part_yaw: float, tool_yaw: float,
           place_yaw: Optional[float] = None) -> list:
        """``grips`` less the track's dropped ones (all of them dropped: all again)."""
        every = grips(part, part_yaw, tool_yaw, place_yaw)
        left = [g for g in every if round(g, 2) not in self.dropped.get(track_id, ())]
        if not left:
            self.dropped.pop(track_id, None)
        return left or every

    def drop(self, track_id: int, found) -> None:
        """The grip yaw of a lead ``found`` (``LineCycles.found``; a str: none) found no tf in the
        track's cycle: not offered again."""
        if not isinstance(found, str):
            self.dropped.setdefault(track_id, set()).add(round(found[4], 2))


def puts(part, place: np.ndarray, slot_yaw: float, grip: float, filled: list, finger: tuple,
         margin: float) -> list:
    """rad: the tool's yaws at a tray slot (its part's centre at ``place``, the slot's yaw
    ``slot_yaw``) for ``part`` gripped at ``grip``, preferred first, each only where the open
    fingers clear every part in the tray by ``FINGER_MARGIN`` (module docstring; none: the slot
    cannot take the part now); ``filled``: the tray's parts' footprints (``in_tray``);
    ``finger``: (thickness, width), m; ``margin``: the open fingers' clearance around the part (m)."""
    own = nearest_branch(grip, slot_yaw)
    symmetry = part_symmetry(part)
    others = ([grip] if symmetry <= 0.0 else
              [nearest_branch(grip, own + symmetry)] if symmetry < math.pi - 1e-9 else [])
    opening = grasp_width(part) + margin
    out = []
    for yaw in [own] + [y for y in others if abs(y - own) > 1e-9]:
        if all(tray_clearance(place, yaw, opening, finger, f) >= FINGER_MARGIN for f in filled):
            out.append(yaw)
    return out


def in_tray(pick, keep: list) -> list:
    """The footprints (``tray_clearance``) of the parts the tasks ``keep`` (indices into
    ``pick.tasks``) put in the tray: a box's rectangle, its x axis at the task's place yaw (the
    axis its fingers closed along), a cylinder's disc."""
    parts = {p.name: p for p in pick.parts}
    out = []
    for k in keep:
        task = pick.tasks[k]
        if task.slot is None:
            continue
        part = parts[task.part]
        centre = place_point(pick, "slot", task.slot, part)[:2]
        if part.shape == "cylinder":
            out.append((centre, 0.5 * float(part.size[0])))
            continue
        yaw = place_target(pick, task)[2]  # (a line's task: its place_yaw)
        out.append((centre, _rectangle(centre, yaw, 0.5 * float(part.size[0]), 0.5 * float(part.size[1]))))
    return out


def tray_clearance(place, yaw: float, opening: float, finger: tuple, footprint) -> float:
    """m: the gap between the nearer open finger of the tool at ``place`` turned to ``yaw`` (each a
    rectangle from half the ``opening`` outward by the finger's thickness, as wide as the finger:
    ``grasp_gate``) and a tray part's ``footprint`` — (centre, radius) of a disc, or (centre,
    corners) of a rectangle: there the largest separation along the two rectangles' edge normals,
    never more than the true gap; negative where they overlap."""
    centre, shape = footprint
    axis = (math.cos(yaw), math.sin(yaw))
    if np.isscalar(shape):
        return finger_clearance(place, axis, opening, finger, centre, float(shape))
    inner, outer, half = 0.5 * opening, 0.5 * opening + finger[0], 0.5 * finger[1]
    gaps = []
    for side in (1.0, -1.0):
        mid = np.asarray(place, float)[:2] + side * 0.5 * (inner + outer) * np.array(axis)
        own = _rectangle(mid, yaw, 0.5 * (outer - inner), half)
        gaps.append(max(_separation(own, shape, n) for n in _normals(own) + _normals(shape)))
    return min(gaps)


def _rectangle(centre, yaw: float, half_x: float, half_y: float) -> np.ndarray:
    """4 × 2: the corners of a rectangle centred at ``centre`` (xy), its x axis at ``yaw``."""
    c, s = math.cos(yaw), math.sin(yaw)
    local = np.array([[half_x, half_y], [-half_x, half_y], [-half_x, -half_y], [half_x, -half_y]])
    return np.asarray(centre, float)[:2] + local @ np.array([[c, s], [-s, c]])


def _normals(corners: np.ndarray) -> list:
    edges = np.diff(np.vstack([corners, corners[:1]]), axis=0)[:2]
    return [np.array([-e[1], e[0]]) / np.linalg.norm(e) for e in edges]


def _separation(a: np.ndarray, b: np.ndarray, n: np.ndarray) -> float:
    """m: how far apart the projections of the convex corner sets ``a`` and ``b`` on ``n`` lie."""
    pa, pb = a @ n, b @ n
    return float(max(pb.min() - pa.max(), pa.min() - pb.max()))


def grip_axis(yaw: float) -> tuple:
    """The fingers' closing axis (world) of the tool at ``yaw`` (rad)."""
    return (math.cos(yaw), math.sin(yaw), 0.0)


def logged(found, cycle) -> dict:
    """The decision log's ``wait`` (s, the lead ``found`` waited for a posture; None: no lead) and
    ``yaws_deg`` (the cycle's grip and place yaws, deg) of a chosen task."""
    return {"wait": None if isinstance(found, str) else found[2],
            "yaws_deg": [round(math.degrees(y), 1) for y in cycle.yaws]}
