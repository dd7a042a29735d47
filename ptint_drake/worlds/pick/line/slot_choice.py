"""Which free tray slot a line's pick takes (issue 44: ``pick.line.catalog[*].fill``).

A kind's ``slots`` were filled in the order listed.  On ``line_two_belts`` (seed 25, commit
ec29df7) that put the first cubes in the tray's column farthest from the belts (x = 0.06 m): its
first carry passed the waist axis and took a via (2.48 s against 0.8–1.3 s for the near column),
and from there the next approach turned the wrist farthest — the burst's last part was lost 0.9 s
before its deadline.  ``fill: cycle`` (the default) asks the min-tf model instead
(``LineCycles.phases``, the whole cycle from the tool's present point: its carry, place and
retreat to that slot) for the ``NEAREST`` free slots nearest the grasp point (horizontal
distance: a cheap first cut, so a decision asks the model for one more cycle, not one per free
slot; the listed order breaks a tie in distance; a slot with no cycle — a phase with no tf, or no
place yaw keeping the open fingers clear of the tray's parts, ``grip.puts`` — makes room for the
next nearest), and takes the shorter cycle (the nearer slot on a tie).  ``fill: order`` keeps the listed
order (a kit filled in a set order).  The next approach, from where the place leaves the tool, is
not in the choice: the next part is not chosen yet.
"""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.phase_time import NoTfFits

NEAREST = 2  # free slots the model is asked for, the nearest the grasp point


def nearest(pick, kind, free: list, point) -> list:
    """The ``free`` slots (indices into ``pick.tray.slots``) by the horizontal distance of their
    place points for a part of ``kind`` (a ``PartConfig``) from ``point``, nearest first, the
    listed order breaking a tie."""
    at = np.asarray(point, dtype=float)[:2]
    distance = {j: float(np.linalg.norm(place_point(pick, "slot", j, kind)[:2] - at)) for j in free}
    return sorted(free, key=lambda j: (round(distance[j], 6), free.index(j)))


def choose(cycle_of, candidates: list) -> tuple:
    """(slot, ``Cycle``) of the shortest ``cycle_of(slot)`` (the first on a tie) among the first
    ``NEAREST`` of the ``candidates`` (nearest first) that have one: a candidate whose cycle has
    no tf (``NoTfFits``: a phase, or no place yaw clearing the tray's parts, ``grip.puts``) is
    passed over for the next; the last error raised where none has one."""
    found, error = [], None
    for slot in candidates:
        try:
            found.append((slot, cycle_of(slot)))
        except NoTfFits as e:
            error = e
        if len(found) == NEAREST:
            break
    if not found:
        raise error
    best = found[0]
    for pair in found[1:]:
        if pair[1].total < best[1].total - 1e-9:
            best = pair
    return best
