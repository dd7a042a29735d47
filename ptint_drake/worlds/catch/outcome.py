"""What a catch run measured (issue 46): the ball's contacts (``BallContacts``) and the named
outcome of the run from the logged truth (``catch_metrics``; the rule is ``run``'s docstring)."""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import LeafSystem

from ptint_drake.worlds.catch.ball import BALL_DIAMETER


PALM = "gripper_base"
HAND_BODIES = (PALM, "left_finger", "right_finger")


class BallContacts(LeafSystem):
    """At every step of the plant, the bodies touching the ball and the peak force on it by body
    (``touched``: name → N, the largest norm of the body's summed contact forces, a finger pinching
    the ball with its pad and its stem at once counted whole; a dict shared across the run's
    diagrams), and the impact (``impact``,
    shared the same way): ``time``, when the palm first touched the ball; ``axis``, the direction of
    that first palm force (the palm's normal, out of the palm); ``peak``, the largest component along
    it of the net contact force on the ball — the force that stops the ball's approach.  The jaws'
    squeeze acts along the closing axis, across the palm's normal, and the two jaws' forces cancel
    in the net, so the grip (up to the driver's force limit, held for the whole catch) is not in
    ``peak`` while it is in ``touched``'s finger entries."""

    def __init__(self, plant, ball, touched: dict, impact: dict | None = None):
        super().__init__()
        self._plant, self._ball, self.touched = plant, ball.index(), touched
        self.impact = {} if impact is None else impact
        self.DeclareAbstractInputPort("contact_results", AbstractValue.Make(ContactResults()))
        self.DeclarePeriodicPublishEvent(plant.time_step(), 0.0, self._record)

    def _record(self, context) -> None:
        results = self.get_input_port().Eval(context)
        by_body = {}
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            a, b = info.bodyA_index(), info.bodyB_index()
            if self._ball not in (a, b):
                continue
            other = self._plant.get_body(b if a == self._ball else a).name()
            on_ball = np.asarray(info.contact_force()) * (1.0 if b == self._ball else -1.0)
            by_body[other] = by_body.get(other, np.zeros(3)) + on_ball
        for other, force in by_body.items():  # a body may touch the ball at more than one point
            self.touched[other] = max(self.touched.get(other, 0.0), float(np.linalg.norm(force)))
        net, palm = sum(by_body.values(), np.zeros(3)), by_body.get(PALM)
        if palm is not None and "axis" not in self.impact and np.linalg.norm(palm) > 0.0:
            self.impact.update(time=context.get_time(), axis=palm / np.linalg.norm(palm), peak=0.0)
        if "axis" in self.impact:
            self.impact["peak"] = max(self.impact["peak"], float(net @ self.impact["axis"]))


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
