"""The catch planner (issue 46): from the ball's estimate, the catch time and point, the hand's
orientation, and what the controller and the gripper are given.

``Planner.plan`` (at the end of the sensing, t_plan): the ball's predicted centre
p(t) = p̂ + v̂ Δ + ½ â Δ² on a 10 ms grid of candidate catch times; a candidate is kept when the
hand reaches it with its approach axis within ``APPROACH_CONE_DEG`` of the ball's incoming
direction (Drake's ``InverseKinematics`` with the joint limits, nearest the present posture), above
``FLOOR_Z``, and when t_c − t_plan ≥ tf_min: the joint-speed bound max_j |Δq_j| ξ̇_max / q̇_max,j
(ξ̇_max of the TBG with the catch's β) × ``TORQUE_MARGIN`` (the torque term of the oracle's
feasibility model, which is not binding on the arm's tf at these speeds, as a margin).  Of those, the
one nearest the hand's present tip (least motion) is chosen; none: ``not reachable``.

What the controller and the hand are then given is ``target``'s.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve

from ptint_drake.systems.task.tbg import tbg_profile

APPROACH_CONE_DEG = 25.0
FLOOR_Z = 0.2
TORQUE_MARGIN = 1.25
GRID = 0.01
HORIZON = 1.0


@dataclass(frozen=True)
class Plan:
    """t_plan, t_catch (s), the catch point (m), the hand's orientation there and the catch posture."""

    t_plan: float
    t_catch: float
    point: np.ndarray
    R: np.ndarray
    q: np.ndarray
    tf_min: float


def predict(estimate: np.ndarray, dt) -> np.ndarray:
    """The ball's centre ``dt`` after the estimate [p, v, a] (a: the estimate's, gravity with drag)."""
    p, v, a = estimate[0:3], estimate[3:6], estimate[6:9]
    return p + np.outer(dt, v) + 0.5 * np.outer(np.square(dt), a)


class Planner:
    """Catch plans for one arm with its hand (module docstring)."""

    def __init__(self, plant, tip: str, beta: float):
        self.plant, self.frame = plant, plant.GetFrameByName(tip)
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

    def plan(self, estimate: np.ndarray, t_plan: float, q_arm: np.ndarray) -> Optional[Plan]:
        q_now = np.asarray(q_arm, float)
        x_now = self.tip(q_now)[0]
        times = t_plan + np.arange(GRID, HORIZON, GRID)
        points = predict(estimate, times - t_plan)
        velocities = estimate[3:6] + np.outer(times - t_plan, estimate[6:9])
        best = None
        for t_c, p, v in sorted(zip(times, points, velocities), key=lambda c: np.linalg.norm(c[1] - x_now)):
            if p[2] < FLOOR_Z or np.linalg.norm(p - x_now) > 0.5:
                continue
            q = self.ik(p, -v / np.linalg.norm(v), q_now)
            if q is None:
                continue
            tf = TORQUE_MARGIN * self.xi_d_max * float(np.max(np.abs(q[:7] - q_now[:7]) / self.v_max))
            if t_c - t_plan >= max(tf, 0.1):
                best = Plan(t_plan, float(t_c), p, self.tip(q)[1], q, tf)
                break
        return best
