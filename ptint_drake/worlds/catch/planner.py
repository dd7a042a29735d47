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

``CatchTarget`` gives the controller the catch point (``target``: [x, 0, 0]) and the hand's
orientation (``target_rotation``: [R, 0, 0]): the start pose until t_plan, then the ball's
predicted centre at t_catch, revised from the estimate every millisecond until ``REVISE_UNTIL`` s
before t_catch (the hand then occludes the ball), then held.  ``CloseCommand`` opens the hand to
its pre-shape and closes it at t_close = t_catch − (pre-shape − ball) / 2 / jaw speed: the jaws
meet the ball when it reaches the fingertip centre.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.solvers import Solve
from pydrake.systems.framework import BasicVector, LeafSystem

from ptint_drake.controllers.slot import TargetView
from ptint_drake.systems.task.tbg import tbg_profile

APPROACH_CONE_DEG = 25.0
FLOOR_Z = 0.2
TORQUE_MARGIN = 1.25
GRID = 0.01
HORIZON = 1.0
REVISE_UNTIL = 0.03


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


class CatchTarget(LeafSystem):
    """The controller's target and orientation (module docstring).  Input ``estimate`` (9)."""

    def __init__(self, start: np.ndarray, R_start: np.ndarray, plan: Optional[Plan]):
        super().__init__()
        self._plan, self._start, self._R0 = plan, np.asarray(start, float), np.asarray(R_start, float)
        self._in = self.DeclareVectorInputPort("estimate", 9)
        self._point = self.DeclareDiscreteState(BasicVector(self._start))
        self.DeclarePeriodicDiscreteUpdateEvent(0.001, 0.0, self._update)
        self.DeclareVectorOutputPort("target", 9, self._target, {self.xd_ticket()})
        self.DeclareVectorOutputPort("target_rotation", 15, self._rotation, {self.time_ticket()})

    def _update(self, context, state) -> None:
        plan, t = self._plan, context.get_time()
        if plan is None or t < plan.t_plan or t > plan.t_catch - REVISE_UNTIL:
            return
        estimate = self._in.Eval(context)
        if np.any(estimate[3:6]):
            state.get_mutable_vector().SetFromVector(predict(estimate, [plan.t_catch - t])[0])

    def _target(self, context, output) -> None:
        output.SetFromVector(np.concatenate([context.get_discrete_state_vector().value(), np.zeros(6)]))

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


def close_time(plan: Optional[Plan], preshape: float, diameter: float, speed: float) -> float:
    """When the jaws start closing (module docstring); never without a plan."""
    if plan is None:
        return float("inf")
    return plan.t_catch - 0.5 * (preshape - diameter) / speed
