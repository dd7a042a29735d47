"""The catch planner (issue 46): from the ball's estimate, the catch time and point, the hand's
orientation, and what the controller and the gripper are given.

``Planner.plan`` (at a time t_plan): the ball's predicted centre and velocity along the estimate's
dragged flight (``flight.propagate`` from [p̂, v̂] with the drag c the estimate's â carries) on a
10 ms grid of candidate catch times; a candidate is kept when the hand reaches it with its
approach axis within ``APPROACH_CONE_DEG`` of the ball's incoming direction (Drake's
``InverseKinematics`` with the joint limits, nearest the present posture), above ``FLOOR_Z``, and
when t_c − t_plan ≥ tf_min: the joint-speed bound max_j |Δq_j| ξ̇_max / q̇_max,j (ξ̇_max of the TBG
with the catch's β) × ``TORQUE_MARGIN``, and at least ``MIN_TF``; Δq to the catch posture and,
with velocity matching, to the posture where the matching starts (½ τ_m u before the catch
point: the approach goes there first; on throw 58 its elbow ran at 1.25 of its limit half way
when only the catch posture was bounded, 0.90 without matching); where that is too late, the
candidate is tried with half the matched velocity, then none (the catch before the matching).  The margin is 1: the torque
term of the oracle's feasibility model is not binding on the arm's tf at these speeds, and a
margin of 1.25 (as first set) refused throws 58, 67 and 147, which the oracle calls reachable
(the straight joint-space bound is already above the oracle's tf on them) and which are caught
without it.  Of those,
the one nearest the hand's present tip (least motion) is chosen.  None: the plan is refused now;
``Planner.hopeless`` tells whether any candidate is left at all (a point in reach with the hand
turned to it, whatever the time: the ball may still come), i.e. whether to try again later.

``Planner.holds`` re-checks a standing plan against a newer estimate: its catch time's point and
incoming direction re-predicted, still above the floor and reachable (IK from the plan's
posture).  Its timing is not re-checked: the speed bound of ``tf_needed`` is the whole profile's
from rest, not the rest of a profile under way (checked so, mid-way, it refused plans the arm
then met, and each replacement, nearest the hand, was an earlier, shorter catch).  A plan that
replaces one takes the candidate times nearest the old catch time first.

The hand's velocity at the catch (``target``) is the plan's ``velocity`` u
(``matched_velocity``): the nearest to ``catch.match`` × v_c that joint speeds within
``SPEED_SHARE`` of each joint's limit give at the catch posture with the orientation held.  A
fraction of v_c alone (as first done: the matched velocity's J⁺ joint speeds scaled into the
limits) was capped at m = 0.12–0.20 by the elbow's 75 °/s, which binds along the ball's path at
every catch posture (an LP over the posture's self-motion, and 30 other IK postures per catch
point on throws 0–9, moved that bound by ≤ 0.01); the other joints can still match v_c's
components across the path, so u, not parallel to v_c, takes 16–25 % off the ball's speed
relative to the hand where m v_c took 12–18 % (throws 0–7 at their plans' postures; uncapped,
0.3 of v_c asked the elbow for 1.8–2.3 times its limit, which the simulated plant does not
enforce: nothing else would show it).  ``match`` is u's component along v_c over |v_c|.

What the controller and the hand are then given is ``target``'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.solvers import Solve
from scipy.optimize import minimize

from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.worlds.catch.flight import from_estimate, propagate

APPROACH_CONE_DEG = 25.0
FLOOR_Z = 0.2
TORQUE_MARGIN = 1.0
GRID = 0.01
HORIZON = 1.0
MIN_TF = 0.1  # s
REACH = 0.5  # m: candidates farther than this from the hand's tip are not tried
SPEED_SHARE = 0.8  # of a joint's speed limit the matched velocity may take


@dataclass(frozen=True)
class Plan:
    """t_plan, t_catch (s), the catch point (m), the hand's orientation there and the catch posture."""

    t_plan: float
    t_catch: float
    point: np.ndarray
    R: np.ndarray
    q: np.ndarray
    tf_min: float
    match: float = 0.0  # the hand's velocity at the catch along the ball's, over the ball's speed
    velocity: Optional[np.ndarray] = None  # the hand's velocity at the catch (m/s, world); None: 0


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
        self.match_time = float(match_time)
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
        self._left = False
        for t_c, p, v in self.candidates(estimate, t_plan, self.tip(q_now)[0], near):
            q = self.ik(p, -v / np.linalg.norm(v), q_now)
            if q is None:
                continue
            self._left = True
            tf = self.tf_needed(q_now, q)
            if t_c - t_plan < max(tf, MIN_TF):
                continue
            full = self.matched_velocity(q, v)
            for u in (full, 0.5 * full, 0.0 * full):  # as much matching as the time allows
                tf_u = max(tf, self._tf_to_ramp(q_now, q, p, v, u))
                if t_c - t_plan >= max(tf_u, MIN_TF):
                    return Plan(t_plan, float(t_c), p, self.tip(q)[1], q, tf_u, float(u @ v / (v @ v)), u)
        return None

    def _tf_to_ramp(self, q_now, q, p, v, u) -> float:
        """``tf_needed`` to the posture at the matching's start, ½ τ_m u before the catch point
        (``target``: the reference waits there until the last τ_m); 0 without matching or when
        that point has no IK solution (the catch posture's bound then stands alone)."""
        if not np.any(u):
            return 0.0
        q_ramp = self.ik(p - 0.5 * self.match_time * u, -v / np.linalg.norm(v), q)
        return 0.0 if q_ramp is None else self.tf_needed(q_now, q_ramp)

    def matched_velocity(self, q, v) -> np.ndarray:
        """The hand's velocity at the catch at posture ``q`` for the ball's velocity ``v``: the
        nearest to ``catch.match`` × v that joint speeds within ``SPEED_SHARE`` of each joint's
        limit give with the orientation held, u = J_v q̇ with J_ω q̇ = 0 and |q̇_j| ≤ share ×
        q̇_max,j (``scipy.optimize.minimize``, SLSQP; a 1e-6 weight on |q̇|² makes it unique).
        Not a fraction of v: where the elbow's limit caps the speed along v, the other joints
        still match the components of v across it (module docstring)."""
        if self.match <= 0.0:
            return np.zeros(3)
        self.plant.SetPositions(self.context, q)
        world = self.plant.world_frame()
        J = self.plant.CalcJacobianSpatialVelocity(self.context, JacobianWrtVariable.kV, self.frame,
                                                   np.zeros(3), world, world)[:, :7]
        goal = self.match * np.asarray(v, float)
        bounds = [(-SPEED_SHARE * m, SPEED_SHARE * m) for m in self.v_max]
        result = minimize(lambda qd: np.sum((J[3:] @ qd - goal) ** 2) + 1e-6 * qd @ qd, np.zeros(7),
                          jac=lambda qd: 2.0 * J[3:].T @ (J[3:] @ qd - goal) + 2e-6 * qd,
                          bounds=bounds, constraints=[{"type": "eq", "fun": lambda qd: J[:3] @ qd,
                                                       "jac": lambda qd: J[:3]}], method="SLSQP")
        return J[3:] @ result.x

    def hopeless(self) -> bool:
        """After a refused ``plan``: no candidate was in reach at all (no point to try again)."""
        return not self._left

    def holds(self, plan: Plan, estimate: np.ndarray, t: float) -> bool:
        """Whether ``plan`` still holds at ``t`` with the newer ``estimate`` (module docstring)."""
        if plan.t_catch - t < 1e-9:
            return True
        p, v = np.split(flight_states(estimate, [plan.t_catch - t])[0], 2)
        return p[2] >= FLOOR_Z and self.ik(p, -v / np.linalg.norm(v), plan.q) is not None
