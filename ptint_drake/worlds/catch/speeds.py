"""The joint speeds a catch plan asks of the arm (issue 46), evaluated before the arm moves.

The simulated plant does not enforce the joints' speed limits, so the planner must.  A bound on
the joint-space distance alone (max_j |Δq_j| ξ̇_max / q̇_max,j) does not: the law drives the hand
along a straight *task-space* line, on which the joints do not move in proportion (throw 58: the
elbow at 1.31 of its limit half way through an approach that bound put at 0.88), and in the last
``match_time`` the moving catch target adds its own velocity.

``peak_ratio`` follows the whole reference of a plan as the law drives it.  The pose error
decays with the TBG of the plan's segment (t_plan to t_catch, β): with ϵ, δ ≈ 0 and the surface
starting at rest (s(t0) = 0), ė = −α e gives e(t) = e(t0) ξ(t), so

    x(t) = x_r(t) + (x_now − x_r(t_plan)) ξ(t),     ẋ = ẋ_r + (x_now − x_r(t_plan)) ξ̇
    R(t) = exp(ξ r0) R_c,  ω = ξ̇ r0,  r0 = log(R_now R_cᵀ)

with x_r, ẋ_r the moving target of ``target.catch_reference`` for the catch point p_c and the
ball's velocity v_c there (fixed along the predicted flight).  The joints follow by closed-loop
differential kinematics, q̇ = J⁺ ([ω; ẋ] + ``FEEDBACK`` [rotation error; x − fk(q)]) (J the tip's
spatial Jacobian: 7 joints, 6 task coordinates, the minimum-norm solution; the controller's
null-space pull to the catch posture added in J's null space at its rate, ``NULL_RATE``), on a
grid of ``STEP`` s, through the brake after the catch (``target.braking``: the posture moves on
while the hand still has the matched speed; throw 47 reached 1.13 of a limit there).  The result is the
largest |q̇_j| / q̇_max,j on the grid, each joint's speed raised by |ξ̇| ``REVISION`` ‖row j of J⁺'s
translation columns‖: room for a revision of the catch point by ``REVISION`` in any direction
early in the approach (the estimate after 0.15 s of flight moves the catch point by 1–7 cm in
the next 100 ms: throws 0, 19, 35, 55, 58), which the law folds into the rest of its ξ profile.
Without that room the realized speeds were up to 1.6 times the modelled ones (throw 55: 1.22
against 0.76).  What is left to the planner's margin (``planner.SPEED_SHARE``) is the law's lag
and the late corrections.
"""

from __future__ import annotations

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.multibody.tree import JacobianWrtVariable

from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.worlds.catch.target import BRAKE_TIME, _ramp, braking

STEP = 0.005  # s
FEEDBACK = 20.0  # 1/s: the differential kinematics' pull back onto the modelled path
NULL_RATE = 2.0  # 1/s: the controller's null-space pull to the catch posture (null_space_rate)
REVISION = 0.04  # m: the catch point's revision the approach must leave room for (module docstring)


def _rotvec(R: np.ndarray) -> np.ndarray:
    """log(R) as a rotation vector (axis × angle)."""
    aa = RotationMatrix(R).ToAngleAxis()
    return aa.axis() * aa.angle()


def _exp(r: np.ndarray) -> np.ndarray:
    """exp of the rotation vector ``r`` (Rodrigues)."""
    angle = float(np.linalg.norm(r))
    if angle < 1e-12:
        return np.eye(3)
    k = r / angle
    Kx = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * Kx + (1.0 - np.cos(angle)) * Kx @ Kx


def target_path(t: np.ndarray, t_catch: float, p_c: np.ndarray, v_c: np.ndarray, m: float,
                tau_m: float) -> tuple:
    """The moving target's x_r, ẋ_r (len(t) × 3 each) for the catch (p_c, v_c) at ``t_catch``,
    and after it the brake (``target.braking``)."""
    x_r, xd_r = np.empty((len(t), 3)), np.empty((len(t), 3))
    for k, s in enumerate(t):
        if s <= t_catch:
            S, g, _ = _ramp((t_catch - s) / tau_m)
            x_r[k], xd_r[k] = p_c - m * tau_m * S * v_c, m * g * v_c
        else:
            row = braking(np.concatenate([p_c, m * v_c, np.zeros(3)]), s - t_catch)
            x_r[k], xd_r[k] = row[0:3], row[3:6]
    return x_r, xd_r


def peak_ratio(planner, q_now: np.ndarray, t_plan: float, t_catch: float, p_c: np.ndarray,
               v_c: np.ndarray, R_c: np.ndarray, m: float, tau_m: float, beta: float,
               q_goal=None) -> float:
    """The largest joint speed over its limit along the plan's modelled motion, to the brake's
    end (module docstring); ``planner`` gives the arm's plant, tip frame and speed limits,
    ``q_goal`` the catch posture the law's null-space term pulls to (None: none)."""
    tf = t_catch - t_plan
    n = max(int(np.ceil((tf + BRAKE_TIME) / STEP)), 2)
    t = t_plan + (tf + BRAKE_TIME) * np.arange(n + 1) / n
    xi, xi_d, _, _ = tbg_profile(t - t_plan, tf, beta)
    x_r, xd_r = target_path(t, t_catch, p_c, v_c, m, tau_m)
    x_now, R_now = planner.tip(q_now)
    e0, r0 = x_now - x_r[0], _rotvec(R_now @ R_c.T)
    plant, context, frame, world = planner.plant, planner.context, planner.frame, planner.plant.world_frame()
    q, dt, worst = np.array(q_now, float), t[1] - t[0], 0.0
    for k in range(n + 1):
        plant.SetPositions(context, q)
        X = frame.CalcPoseInWorld(context)
        R_want = _exp(xi[k] * r0) @ R_c
        err = np.concatenate([_rotvec(R_want @ X.rotation().matrix().T),
                              x_r[k] + e0 * xi[k] - X.translation()])
        J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3), world,
                                              world)[:, :7]
        twist = np.concatenate([xi_d[k] * r0, xd_r[k] + e0 * xi_d[k]])
        J_plus = np.linalg.pinv(J)
        qd = J_plus @ twist
        if q_goal is not None:
            qd = qd + (np.eye(7) - J_plus @ J) @ (NULL_RATE * (q_goal[:7] - q[:7]))
        revision = abs(xi_d[k]) * REVISION * np.linalg.norm(J_plus[:, 3:6], axis=1)
        worst = max(worst, float(np.max((np.abs(qd) + revision) / planner.v_max)))
        q[:7] += (qd + FEEDBACK * (J_plus @ err)) * dt
    return worst
