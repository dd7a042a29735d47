"""What the catch planner gives the controller and the hand (issue 46): the moving catch target,
the hand's orientation, and the close command.

``CatchTarget`` (input ``estimate``, the ball's [p̂, v̂, â] at t): before t_plan the hand's
start pose.  From t_plan on, the prescribed-time law aims at a *moving* target that reaches the
ball's predicted centre at exactly t_catch:

    p_c(t)  = the estimate's flight at T = t_catch − t   (``flight.propagate`` from [p̂, v̂]
                                                        with the drag c of â; along that
                                                        flight d/dt p_c = 0)
    v_c(t)  = the ball's velocity there
    x_r(t)  = p_c − m v_c τ_m S(x),  ẋ_r = m v_c g(x),  ẍ_r = −(m v_c / τ_m) g'(x),  x = min(T / τ_m, 1)
    g(x)    = 1 − 10x³ + 15x⁴ − 6x⁵  (from 1 at x = 0 to 0 at x = 1, flat at both ends),
    S(x)    = ∫₀ˣ g = x − 2.5x⁴ + 3x⁵ − x⁶  (S(1) = ½)

so that x_r(t_catch) = p_c, the ball's estimated centre, and ẋ_r(t_catch) = m v_c: the hand
arrives moving with the ball at the fraction m (the plan's: ``catch.match`` within the joints'
speed limits, ``planner.Planner.matchable``; 0: it waits at the point) and
the ball enters between the jaws at (1 − m) of its speed.  Before the last τ_m
(``catch.match_time``) the target is the point ½ m τ_m |v_c| back along the ball's path;
in the last τ_m the hand speeds up along the path to m v_c, with no jump in its reference's
acceleration at either end and the largest, 1.875 m |v_c| / τ_m, half way (an exponential
onset instead, as first tried, asked for 2 m |v_c| / τ_m at the catch itself: 48 m/s² at
τ_m = 0.05 s and 4 m/s, which the arm did not follow: the hand 7–10 mm behind its target at
the catch).  Every term is recomputed from the estimate each time the controller reads it, so
the law tracks the catch point as the estimate converges (the paper's interception of a known
moving target, the knowledge improving as frames come in); from ``freeze`` s before t_catch
(``catch.freeze``) the estimate is held: the hand then occludes the ball and the ball, once
held, moves with the hand.

After t_catch the target brakes the same way: ẋ_r = u g(y), x_r = x_c + u τ_b S(y),
y = min((t − t_catch) / τ_b, 1), u = ẋ_r(t_catch), τ_b = ``BRAKE_TIME``: at rest after τ_b,
½ u τ_b further on.

``CloseCommand`` opens the hand to its pre-shape and closes it at ``close_time``: t_catch + lag −
(pre-shape − ball) / 2 / jaw speed (each jaw moves at the driver's speed), so the jaws reach the
ball's diameter ``lag`` (``catch.close_lag``) after its centre reaches the fingertip centre.  The
palm is 2.5 mm deeper (its face 35 mm below the fingertip centre, the ball's radius 32.5 mm): at
3–5 m/s the ball touches it < 1 ms after t_catch, and the palm stops the ball's approach 3–3.5
ms after that first touch (the ball shot into the open palm at 2, 3.5 and 5 m/s, at 1 and 0.25 ms
steps; it leaves the palm 7–8 ms after the touch, at 0.42–0.48 of its speed).  The default lag,
4 ms, lets the palm take the impact before the jaws grip: closed to reach the ball at t_catch (lag
0, as first set), the pads met the ball while it still slid toward the palm at nearly its full
relative speed, and their friction (the pads' μ = 1 on the jaws' squeeze) added 10–28 N along the
palm's normal to the impact whether the hand moved with the ball or not (throws 0–19: 17 N median
with matching, 18 N without; docs/catch.md).  The jaws still reach the ball while it rests on the
palm, before it rebounds.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from ptint_drake.controllers.slot import TargetView
from ptint_drake.worlds.catch.flight import from_estimate, propagate

BRAKE_TIME = 0.1  # s


def _ramp(x: float) -> tuple:
    """(S, g, g') of the module docstring at x (clipped to [0, 1])."""
    x = min(max(x, 0.0), 1.0)
    x3 = x * x * x
    return (x - 2.5 * x3 * x + 3.0 * x3 * x * x - x3 * x3, 1.0 - 10.0 * x3 + 15.0 * x3 * x - 6.0 * x3 * x * x,
            -30.0 * x * x + 60.0 * x3 - 30.0 * x3 * x)


def catch_reference(estimate: np.ndarray, T: float, m: float, tau_m: float) -> np.ndarray:
    """[x_r, ẋ_r, ẍ_r] (9) of the module docstring from an estimate [p̂, v̂, â], T = t_catch − t."""
    p, v = estimate[0:3], estimate[3:6]
    T = max(T, 0.0)
    state = propagate(p, v, from_estimate(estimate), 0.0, [T])[0] if T > 0.0 else np.concatenate([p, v])
    p_c, v_c = state[0:3], state[3:6]
    S, g, g1 = _ramp(T / tau_m)
    return np.concatenate([p_c - m * tau_m * S * v_c, m * g * v_c, -(m / tau_m) * g1 * v_c])


def braking(at_catch: np.ndarray, tau: float) -> np.ndarray:
    """[x_r, ẋ_r, ẍ_r] ``tau`` s after the catch from the reference there (module docstring)."""
    x, u = at_catch[0:3], at_catch[3:6]
    S, g, g1 = _ramp(tau / BRAKE_TIME)
    return np.concatenate([x + BRAKE_TIME * S * u, g * u, (g1 / BRAKE_TIME) * u])


class CatchTarget(LeafSystem):
    """The controller's target and orientation (module docstring).  Input ``estimate`` (9);
    ``plan``: a ``planner.Plan`` or None (the start pose throughout)."""

    def __init__(self, start: np.ndarray, R_start: np.ndarray, plan, catch):
        super().__init__()
        self._plan, self._start, self._R0 = plan, np.asarray(start, float), np.asarray(R_start, float)
        self._tau_m, self._freeze = float(catch.match_time), float(catch.freeze)
        self._in = self.DeclareVectorInputPort("estimate", 9)
        self._held = self.DeclareDiscreteState(BasicVector(np.zeros(10)))  # [held?, estimate]
        if plan is not None:
            self.DeclarePeriodicDiscreteUpdateEvent(0.001, 0.0, self._hold)
        self.DeclareVectorOutputPort("target", 9, self._target, {self.all_sources_ticket()})
        self.DeclareVectorOutputPort("target_rotation", 15, self._rotation, {self.time_ticket()})

    def _hold(self, context, state) -> None:
        if context.get_time() < self._plan.t_catch - self._freeze:
            state.get_mutable_vector().SetFromVector(np.r_[1.0, self._in.Eval(context)])

    def reference(self, context) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r] at the context's time."""
        plan, t = self._plan, context.get_time()
        if plan is None or t < plan.t_plan:
            return np.concatenate([self._start, np.zeros(6)])
        held = context.get_discrete_state(self._held).get_value()
        live = t < plan.t_catch - self._freeze or held[0] == 0.0
        estimate = self._in.Eval(context) if live else self._extrapolated(held[1:], t)
        if t <= plan.t_catch:
            return catch_reference(estimate, plan.t_catch - t, plan.match, self._tau_m)
        at_catch = catch_reference(self._extrapolated(held[1:], plan.t_catch), 0.0, plan.match, self._tau_m)
        return braking(at_catch, t - plan.t_catch)

    def _extrapolated(self, held: np.ndarray, t: float) -> np.ndarray:
        """The held estimate (taken at the last update before the freeze) moved on to ``t``."""
        dt = t - (self._plan.t_catch - self._freeze)
        dt = max(dt, 0.0)
        p, v, a = held[0:3], held[3:6], held[6:9]
        return np.concatenate([p + v * dt + 0.5 * a * dt * dt, v + a * dt, a])

    def _target(self, context, output) -> None:
        output.SetFromVector(self.reference(context))

    def _rotation(self, context, output) -> None:
        plan = self._plan
        R = plan.R if plan is not None and context.get_time() >= plan.t_plan else self._R0
        output.SetFromVector(np.concatenate([R.reshape(-1), np.zeros(6)]))


class CloseCommand(LeafSystem):
    """The gripper's opening command: the pre-shape, 0 (close) from ``t_close`` on."""

    def __init__(self, preshape: float, t_close: float):
        super().__init__()
        self.DeclareVectorOutputPort(
            "command", 1, lambda c, o: o.SetAtIndex(0, preshape if c.get_time() < t_close else 0.0),
            {self.time_ticket()})


class CatchTargetView(TargetView):
    """The controller's view of the target: the planner's ports (the ball's estimate through the
    plan), never the station's truth."""

    def __init__(self, target_port, rotation_port):
        self.analytic = None
        self._port, self._rotation_port = target_port, rotation_port

    def port(self):
        return self._port

    def rotation_port(self):
        return self._rotation_port


def close_time(plan, preshape: float, diameter: float, speed: float, lag: float = 0.0) -> float:
    """When the jaws start closing so that they reach the ball's diameter ``lag`` s after t_catch
    (module docstring); never without a plan."""
    if plan is None:
        return float("inf")
    return plan.t_catch + lag - 0.5 * (preshape - diameter) / speed

