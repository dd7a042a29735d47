"""Which free tray slot a line's pick takes (issue 44: ``pick.line.catalog[*].fill``).

A kind's ``slots`` were filled in the order listed.  On ``line_two_belts`` (seed 25, commit
ec29df7) that put the first cubes in the tray's column farthest from the belts (x = 0.06 m): its
first carry passed the waist axis and took a via (2.48 s against 0.8–1.3 s for the near column),
and from there the next approach turned the wrist farthest — the burst's last part was lost 0.9 s
before its deadline.  ``fill: cycle`` (the default) asks the min-tf model instead
(``LineCycles.phases``, the whole cycle from the tool's present point: its carry, place and
retreat to that slot) for the ``NEAREST`` free slots nearest the grasp point (horizontal
distance: a cheap first cut, so a decision asks the model for one more cycle, not one per free
slot; the listed order breaks a tie in distance), and takes the shorter cycle (the nearer slot
on a tie).  ``fill: order`` keeps the listed
order (a kit filled in a set order).  The next approach, from where the place leaves the tool, is
not in the choice: the next part is not chosen yet.
"""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.phase_time import Cycle, NoTfFits

NEAREST = 2  # free slots the model is asked for, the nearest the grasp point


def nearest(pick, kind, free: list, point) -> list:
    """The ``NEAREST`` of the ``free`` slots (indices into ``pick.tray.slots``) whose place points
    for a part of ``kind`` (a ``PartConfig``) are nearest ``point`` horizontally, nearest first,
    the listed order breaking a tie."""
    at = np.asarray(point, dtype=float)[:2]
    distance = {j: float(np.linalg.norm(place_point(pick, "slot", j, kind)[:2] - at)) for j in free}
    return sorted(free, key=lambda j: (round(distance[j], 6), free.index(j)))[:NEAREST]


def choose(cycle_of, candidates: list) -> tuple:
    """(slot, ``Cycle``) of the ``candidates`` whose ``cycle_of(slot)`` is the shortest (the
    first of them on a tie); a candidate whose cycle has no tf (``NoTfFits``) is passed over; the
    last candidate's error raised where none has one."""
    best, error = None, None
    for slot in candidates:
        try:
            cycle: Cycle = cycle_of(slot)
        except NoTfFits as e:
            error = e
            continue
        if best is None or cycle.total < best[1].total - 1e-9:
            best = (slot, cycle)
    if best is None:
        raise error
    return best
