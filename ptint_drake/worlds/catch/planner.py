"""The catch planner (issue 46): from the ball's estimate, the catch time and point, the hand's
orientation, and what the controller and the gripper are given.

``Planner.plan`` (at a time t_plan): the ball's predicted centre and velocity along the estimate's
dragged flight (``flight.propagate`` from [p̂, v̂] with the drag c the estimate's â carries) on a
10 ms grid of candidate catch times; a candidate is kept when the hand reaches it with its
approach axis within ``APPROACH_CONE_DEG`` of the ball's incoming direction (Drake's
``InverseKinematics`` with the joint limits, nearest the present posture), above ``FLOOR_Z``, and
when t_c − t_plan ≥ tf_min: the joint-speed bound max_j |Δq_j| ξ̇_max / q̇_max,j (ξ̇_max of the TBG
with the catch's β) × ``TORQUE_MARGIN``, and at least ``MIN_TF``.  The margin is 1: the torque
term of the oracle's feasibility model is not binding on the arm's tf at these speeds, and a
margin of 1.25 (as first set) refused throws 58, 67 and 147, which the oracle calls reachable
(the straight joint-space bound is already above the oracle's tf on them) and which are caught
without it.  Each such candidate's whole motion is then modelled (``speeds.peak_ratio``: the
approach along the law's task-space line, the moving catch target, the matching, with room for
a revision of the catch point) and kept only when every joint stays within ``SPEED_SHARE`` of
its speed limit, with the largest matched fraction m' ≤ the configured one that does
(``within_limits``; not even m' = 0: refused).  Of those, the one with the largest matched
speed m'|v_c| is chosen (``_fastest_match``), the nearest the hand's present tip among equals
(without matching: the nearest that fits).  None: the plan is refused now;
``Planner.hopeless`` tells whether any candidate is left at all (a point in reach with the hand
turned to it, whatever the time: the ball may still come), i.e. whether to try again later.

``Planner.holds`` re-checks a standing plan against a newer estimate: its catch time's point and
incoming direction re-predicted, still above the floor and reachable (IK from the plan's
posture).  Its timing is not re-checked: the speed bound of ``tf_needed`` is the whole profile's
from rest, not the rest of a profile under way (checked so, mid-way, it refused plans the arm
then met, and each replacement, nearest the hand, was an earlier, shorter catch).  A plan that
replaces one takes the candidate times nearest the old catch time first.

The velocity the hand matches at the catch (``target``) is the plan's ``match``: ``catch.match``,
capped first by ``matchable`` (the matched velocity alone within ``SPEED_SHARE`` of every joint's
limit: uncapped, 0.3 of a 4 m/s ball asked the iiwa's elbow for 1.8–2.3 times its limit) and
then by the whole motion's model above.  Capping the matched velocity alone was not enough: the
realized joint speeds exceeded a limit on 70 of throws 0–99 (the elbow of throw 58 at 1.37), from
the approach along a straight task-space line (which a joint-space bound does not see), the
law's lag and catch-up on it, and the revisions of the catch point corrected late at the
prescribed-time gain (docs/catch.md).  The simulated plant does not enforce speed limits, so
nothing else would show it.

What the controller and the hand are then given is ``target``'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.solvers import Solve
from scipy.optimize import linprog

from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.worlds.catch.flight import from_estimate, propagate
from ptint_drake.worlds.catch.speeds import peak_ratio

APPROACH_CONE_DEG = 25.0
FLOOR_Z = 0.2
TORQUE_MARGIN = 1.0
GRID = 0.01
HORIZON = 1.0
MIN_TF = 0.1  # s
REACH = 0.5  # m: candidates farther than this from the hand's tip are not tried
ROT_SCALE = 0.1  # m/rad: the controller's weighing of the rotation (the catch scenario's)
SPEED_SHARE = 0.8  # of a joint's speed limit the matched velocity may take
MATCH_MARGIN = 1.15  # the matched velocity as modelled: the hand overshoots it near the catch
MATCH_STEPS = 5  # bisection steps for a smaller m when the whole motion exceeds SPEED_SHARE


@dataclass(frozen=True)
class Plan:
    """t_plan, t_catch (s), the catch point (m), the hand's orientation there and the catch posture."""

    t_plan: float
    t_catch: float
    point: np.ndarray
    R: np.ndarray
    q: np.ndarray
    tf_min: float
    match: float = 0.0
    speed_ratio: float = 0.0


def predict(estimate: np.ndarray, dt) -> np.ndarray:
    """The ball's centre ``dt`` (s, one or many) after the estimate [p, v, a] along its dragged
    flight (c from â: ``flight.from_estimate``)."""
    return flight_states(estimate, dt)[:, 0:3]


def flight_states(estimate: np.ndarray, dt) -> np.ndarray:
    """[p, v] (len(dt) × 6) ``dt`` after the estimate [p, v, a] along its dragged flight."""
    estimate = np.asarray(estimate, float)
    return propagate(estimate[0:3], estimate[3:6], from_estimate(estimate), 0.0, dt)


class Planner:
    """Catch plans for one arm with its hand (module docstring)."""

    def __init__(self, plant, tip: str, beta: float, match: float = 0.0, match_time: float = 0.2):
        self.plant, self.frame, self.match = plant, plant.GetFrameByName(tip), float(match)
        self.beta, self.match_time = float(beta), float(match_time)
        self.context = plant.CreateDefaultContext()
        self.v_max = plant.GetVelocityUpperLimits()[:7]
        f = np.linspace(0.0, 1.0, 401)
        self.xi_d_max = float(np.max(np.abs(tbg_profile(f, 1.0, beta)[1])))

    def ik(self, x, approach, guess) -> Optional[np.ndarray]:
        ik = InverseKinematics(self.plant, with_joint_limits=True)
        ik.AddPositionConstraint(self.frame, np.zeros(3), self.plant.world_frame(), x - 1e-4, x + 1e-4)
        ik.AddAngleBetweenVectorsConstraint(self.frame, [0.0, 0.0, 1.0], self.plant.world_frame(), approach,
                                            0.0, np.radians(APPROACH_CONE_DEG))
        ik.prog().AddQuadraticErrorCost(np.eye(7), guess[:7], ik.q()[:7])
        ik.prog().SetInitialGuess(ik.q(), guess)
        result = Solve(ik.prog())
        return result.GetSolution(ik.q()) if result.is_success() else None

    def tip(self, q) -> tuple:
        self.plant.SetPositions(self.context, q)
        X = self.frame.CalcPoseInWorld(self.context)
        return X.translation(), X.rotation().matrix()

    def tf_needed(self, q_from, q_to) -> float:
        """The planner's minimum tf from posture ``q_from`` to ``q_to`` (module docstring)."""
        return TORQUE_MARGIN * self.xi_d_max * float(np.max(np.abs(q_to[:7] - q_from[:7]) / self.v_max))

    def candidates(self, estimate: np.ndarray, t_plan: float, x_now: np.ndarray, near=None) -> list:
        """(t_c, point, velocity) on the grid, above the floor and within ``REACH`` of ``x_now``,
        nearest first (or nearest the time ``near``)."""
        times = t_plan + np.arange(GRID, HORIZON, GRID)
        states = flight_states(estimate, times - t_plan)
        kept = [(t, s[0:3], s[3:6]) for t, s in zip(times, states)
                if s[2] >= FLOOR_Z and np.linalg.norm(s[0:3] - x_now) <= REACH]
        if near is not None:
            return sorted(kept, key=lambda c: abs(c[0] - near))
        return sorted(kept, key=lambda c: np.linalg.norm(c[1] - x_now))

    def plan(self, estimate: np.ndarray, t_plan: float, q_arm: np.ndarray, near=None) -> Optional[Plan]:
        """The catch of the module docstring from ``estimate`` at ``t_plan`` with the arm at
        ``q_arm``, or None (refused now); ``near``: the catch time of a plan it replaces (the
        candidates nearest it first, not the nearest points)."""
        q_now = np.asarray(q_arm, float)
        self._left, kept = False, []
        for k, (t_c, p, v) in enumerate(self.candidates(estimate, t_plan, self.tip(q_now)[0], near)):
            q = self.ik(p, -v / np.linalg.norm(v), q_now)
            if q is None:
                continue
            self._left = True
            tf = self.tf_needed(q_now, q)
            if t_c - t_plan >= max(tf, MIN_TF):
                kept.append((self.matchable(q, v) * float(np.linalg.norm(v)), k, float(t_c), p, v, q, tf))
        return self._fastest_match(kept, q_now, t_plan)

    def _fastest_match(self, kept: list, q_now: np.ndarray, t_plan: float) -> Optional[Plan]:
        """Of the candidates ``kept`` (bound on the matched speed, order, t_c, point, velocity,
        posture, tf), the one whose matched speed m'|v| within the limits (``within_limits``) is
        the largest, the first in order among equals (without matching: the first that fits)."""
        best, best_speed = None, -1.0
        for bound, _, t_c, p, v, q, tf in sorted(kept, key=lambda c: (-c[0], c[1])):
            if bound <= best_speed:
                break  # m' ≤ the matched velocity's own cap: no later one can be faster
            speed = float(np.linalg.norm(v))
            R = self.tip(q)[1]
            fit = self.within_limits(q_now, t_plan, t_c, p, v, R, q, bound / speed)
            if fit is not None and fit[0] * speed > best_speed:
                best, best_speed = Plan(t_plan, t_c, p, R, q, tf, *fit), fit[0] * speed
        return best

    def within_limits(self, q_now, t_plan: float, t_c: float, p, v, R, q, m: float) -> Optional[tuple]:
        """(m', peak) for a catch at (t_c, p, v, R; posture q) from ``q_now``: the largest matched fraction
        m' ≤ ``m`` whose whole modelled motion (``speeds.peak_ratio``) keeps every joint within
        ``SPEED_SHARE`` of its limit, and that motion's peak; None when not even m' = 0 does."""
        def peak(fraction: float) -> float:
            return peak_ratio(self, q_now, t_plan, t_c, p, v, R, MATCH_MARGIN * fraction, self.match_time,
                              self.beta, q)
        top = peak(m)
        if top <= SPEED_SHARE:
            return m, top
        low = peak(0.0) if m > 0.0 else top
        if low > SPEED_SHARE:
            return None
        fit, lo, hi = (0.0, low), 0.0, m
        for _ in range(MATCH_STEPS):  # bisection: the largest m' that fits, within m / 2^steps
            mid = 0.5 * (lo + hi)
            top = peak(mid)
            if top <= SPEED_SHARE:
                fit, lo = (mid, top), mid
            else:
                hi = mid
        return fit

    def matchable(self, q, v) -> float:
        """The fraction of the ball's velocity ``v`` the hand may match at posture ``q``: the
        configured one, or less, so that the joint speeds of the matched hand velocity alone
        (J⁺ with the controller's rotation weighing, the orientation held) stay within
        ``SPEED_SHARE`` of the joints' limits."""
        if self.match <= 0.0:
            return 0.0
        J = self._jacobian(q)
        J = np.vstack([ROT_SCALE * J[:3], J[3:]])
        qd = np.linalg.lstsq(J, np.concatenate([np.zeros(3), v]), rcond=None)[0]
        return float(min(self.match, SPEED_SHARE / np.max(np.abs(qd) / self.v_max)))

    def _jacobian(self, q) -> np.ndarray:
        """The tip's spatial Jacobian [ω; v] over the arm's 7 joint velocities at posture ``q``."""
        self.plant.SetPositions(self.context, q)
        world = self.plant.world_frame()
        return self.plant.CalcJacobianSpatialVelocity(self.context, JacobianWrtVariable.kV, self.frame,
                                                      np.zeros(3), world, world)[:, :7]

    def match_bound(self, q, v) -> float:
        """The largest fraction of the ball's velocity ``v`` the hand can have at posture ``q``
        with its orientation held and every joint at most at its speed limit (a linear program over
        q̇: J_ω q̇ = 0, J_v q̇ = u v/|v|, |q̇_j| ≤ q̇_max,j, u the largest): no matching at this
        posture takes more off the ball's speed relative to the hand, whatever the margins."""
        J = self._jacobian(q)
        speed = float(np.linalg.norm(v))
        direction = np.concatenate([np.zeros(3), np.asarray(v) / speed])
        # unknowns [q̇ (7), u]: maximise u
        result = linprog(np.r_[np.zeros(7), -1.0], A_eq=np.hstack([J, -direction[:, None]]), b_eq=np.zeros(6),
                         bounds=[(-vm, vm) for vm in self.v_max] + [(0.0, None)], method="highs")
        return float(result.x[-1]) / speed if result.status == 0 else 0.0

    def hopeless(self) -> bool:
        """After a refused ``plan``: no candidate was in reach at all (no point to try again)."""
        return not self._left

    def holds(self, plan: Plan, estimate: np.ndarray, t: float) -> bool:
        """Whether ``plan`` still holds at ``t`` with the newer ``estimate`` (module docstring)."""
        if plan.t_catch - t < 1e-9:
            return True
        p, v = np.split(flight_states(estimate, [plan.t_catch - t])[0], 2)
        return p[2] >= FLOOR_Z and self.ik(p, -v / np.linalg.norm(v), plan.q) is not None
