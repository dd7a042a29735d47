"""A line task's phase split by a via, fitted to what its two legs need (issue 44).

Where the plan splits a phase by a via (``route``: around the waist axis; ``obstacles``: above a
part in the way) the via's leg takes the share of the phase's tf that its length takes of the
two legs' (``tasks.Via.share``: the same mean speed on both, so a scripted scenario's times after
it stay where it put them).  A line's task has no such times to keep: its phases come from the
min-tf model (``line.cycle``), and the model asked for each leg on its own (``LineCycles.detours``:
tf₁ for the via's leg, tf₂ for the rest) says what the split must give each.

``split``: the approach (its end is the grasp the scheduler chose, its tf T stretched to it)
is left as it is where T gives each leg its own (share·T ≥ tf₁ and (1 − share)·T ≥ tf₂);
otherwise its tf becomes max(T, tf₁ + tf₂) and its ``via_share`` the share nearest the plan's
that gives each leg its own — at tf₁ + tf₂ exactly tf₁ / (tf₁ + tf₂).  A phase after the grasp
(a carry) has no such end: it takes tf₁ + tf₂ split tf₁ : tf₂ — shorter than the model's
straight way where that way passes the waist axis, the reason for the via (``line_two_belts``
seed 25's first carry: 3.32 s straight, its legs 1.51 + 0.98 s) — unless its tf already fits
within ``SHORTER`` of that.  The rule it replaces stretched the phase to max(tf₁ / share,
tf₂ / (1 − share)) with the length share kept, and never shortened it.

``fitted``: every phase of a task, the plan's vias as ``split`` makes them; a phase the plan does
not split (or no longer: an obstacle's via depends on when the phase passes the parts riding by,
a changed tf may clear it) at least the model's straight tf — an approach too, its grasp then
later (measured at 3d30e76, line_two_belts seed 8: a lead that waited 0.25 s for a posture gave a
grasp 2.3 s after the decision while the cycle's approach from the decision was 3.08 s; the
approach was commanded in 2.06 s, joint 1 at 1.35 × its speed limit; 1 of 237 tasks).
Measured on seed 25 at 1c48563: the second task's carry stretched 0.96 → 2.65 s for a via that
the stretch then made needless; with the split the via's leg took 0.23 s and the carry 0.96 s.
"""

from __future__ import annotations

from typing import Optional

from ptint_drake.config.pick import MoveConfig, PickTaskConfig

DETOUR_PASSES = 3  # plans made to fit a task's vias (``driver.LineDriver._fit``, ``watch``)
SLACK = 1e-3  # s: a leg this much short of its min tf still fits (the fit's tolerance)
SHORTER = 0.05  # s: a phase after the grasp this much longer than its legs need is shortened


def split(move: MoveConfig, first: float, second: float, share: float,
          fixed_end: bool = True) -> Optional[MoveConfig]:
    """None where ``move`` (its tf T, the via's leg taking ``share`` of it) gives the via's leg at
    least ``first`` s and the rest at least ``second`` s (and, unless ``fixed_end``, T is within
    ``SHORTER`` of first + second); else the move both legs fit (module docstring)."""
    tf, need = move.tf, first + second
    fits = share * tf >= first - SLACK and (1.0 - share) * tf >= second - SLACK
    if fits and (fixed_end or tf <= need + SHORTER):
        return None
    if not fixed_end:
        return MoveConfig(need, move.beta, first / need)
    tf = max(tf, need)
    return MoveConfig(tf, move.beta, min(max(share, first / tf), 1.0 - second / tf))


def fitted(task: PickTaskConfig, needs: dict, straight: dict) -> dict:
    """phase → the ``MoveConfig`` it needs instead of ``task``'s: ``needs`` (phase → (tf₁, tf₂,
    share), ``LineCycles.detours``) split (``split``: the approach's end fixed), and a phase
    without a via shorter than its ``straight`` tf (phase → s, the model's) stretched to that."""
    out = {}
    for phase, legs in needs.items():
        move = split(getattr(task, phase), *legs, fixed_end=phase == "approach")
        if move is not None:
            out[phase] = move
    for phase, tf in straight.items():
        move = getattr(task, phase)
        if phase not in needs and move.tf < tf - SLACK:
            out[phase] = MoveConfig(tf, move.beta)
    return out
