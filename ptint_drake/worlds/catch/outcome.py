"""What a catch run measured (issue 46): the ball's contacts (``BallContacts``) and the named
outcome of the run from the logged truth (``catch_metrics``; the rule is ``run``'s docstring)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import LeafSystem

from ptint_drake.worlds.catch.ball import BALL_DIAMETER


class BallContacts(LeafSystem):
    """At every step of the plant, the bodies touching the ball and the peak normal force on it by body
    (``touched``: name → N, a dict shared across the run's diagrams)."""

    def __init__(self, plant, ball, touched: dict):
        super().__init__()
        self._plant, self._ball, self.touched = plant, ball.index(), touched
        self.DeclareAbstractInputPort("contact_results", AbstractValue.Make(ContactResults()))
        self.DeclarePeriodicPublishEvent(plant.time_step(), 0.0, self._record)

    def _record(self, context) -> None:
        results = self.get_input_port().Eval(context)
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            a, b = info.bodyA_index(), info.bodyB_index()
            if self._ball not in (a, b):
                continue
            other = self._plant.get_body(b if a == self._ball else a).name()
            force = float(np.linalg.norm(info.contact_force()))
            self.touched[other] = max(self.touched.get(other, 0.0), force)


HAND_BODIES = ("gripper_base", "left_finger", "right_finger")
HELD_RADIUS = 0.02  # m
GRIP_TOLERANCE = 0.01  # m
LATE_RADIUS = 0.025  # m
# the named outcomes (``run``'s docstring), besides "collision with <body>"
OUTCOMES = ("caught", "not reachable", "slipped out", "late", "closed on nothing", "bounced off")


def _held(d: float, opening: float) -> bool:
    """The ball's centre near the fingertip centre and the jaws stopped on it: above half its
    diameter (the foam ball squeezed by the jaws' force: measured 55 mm on 65 at 40 N) and not
    open beyond it."""
    return d <= HELD_RADIUS and 0.5 * BALL_DIAMETER <= opening <= BALL_DIAMETER + GRIP_TOLERANCE


def outcome(plan, touched: dict, at: dict) -> str:
    """The run's named outcome (``run``'s docstring) from ``at``: per time, (tip-to-ball distance,
    opening)."""
    if plan is None:
        return "not reachable"
    arm = sorted(b for b in touched if b not in HAND_BODIES)
    if arm:
        return f"collision with {arm[0]}"
    times = sorted(at)
    end, early = times[-1], min(times, key=lambda s: abs(s - (plan.t_catch + 0.1)))
    if _held(*at[end]):
        return "caught"
    if _held(*at[early]):
        return "slipped out"
    if at[min(times, key=lambda s: abs(s - plan.t_catch))][0] > LATE_RADIUS:
        return "late"
    if at[end][1] < 0.5 * BALL_DIAMETER:
        return "closed on nothing"
    return "bounced off"
