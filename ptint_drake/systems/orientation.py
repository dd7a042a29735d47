"""Orientation for the interceptor's ``pose`` and ``top_down`` tasks (issue 19).

A target may carry the object frame's orientation R_r(t) with its world-frame angular
velocity ω_r and acceleration ω̇_r (``signals.TARGET_ROTATION``: 15 values).  The task error
stacks the position error and the rotation error, scaled by ``rot_scale`` c (m per rad;
``systems.task``):

    e = [x − x_r;  c e_R],   e_R = log(R R_rᵀ)^∨         (world frame, shorter rotation)
    ė = [ẋ − ẋ_r;  c ė_R],   ė_R = ω − R R_rᵀ ω_r        (the error rotation's angular velocity)
    J = [J_v;  c J_ω]                                     (ė = J q̇ − [ẋ_r; c R R_rᵀ ω_r])

Since d/dt e_R = J_l⁻¹(e_R) ė_R and J_l⁻¹(e) e = e, the ideal surface ė + α e = 0 keeps the
paper's decay law e(t) = e(t0)((ξ + δ)/(ξ(t0) + δ))^α0 for the rotation too, about a fixed
axis.  ``top_down`` replaces R_r by Rz(ψ)·Rx(π): approach axis (z) straight down, ψ the
object's horizontal x-axis angle modulo 180° on the branch nearest the tool's current yaw.
Kinematics only: still model-free.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.eigen_geometry import AngleAxis, Quaternion
from pydrake.math import RollPitchYaw, RotationMatrix
from pydrake.systems.framework import LeafSystem
from pydrake.trajectories import PiecewiseQuaternionSlerp

from ptint_drake.systems.signals import IDENTITY_ROTATION

def rotation_log(Re: np.ndarray) -> np.ndarray:
    """log(Re)^∨ (3): axis × angle of the shorter rotation, angle in [0, π]."""
    q = RotationMatrix(np.asarray(Re, dtype=float)).ToQuaternion()
    w, v = q.w(), np.array([q.x(), q.y(), q.z()])
    if w < 0.0:
        w, v = -w, -v
    n = float(np.linalg.norm(v))
    if n < 1e-12:
        return 2.0 * v / w
    return (2.0 * math.atan2(n, w) / n) * v


def rotation_angle(R: np.ndarray, R_r: np.ndarray) -> float:
    """The full angle (rad) of R_rᵀ R: how far orientation R is from R_r."""
    return float(np.linalg.norm(rotation_log(np.asarray(R) @ np.asarray(R_r).T)))


def skew(w) -> np.ndarray:
    """[w]×, the cross-product matrix of a 3-vector."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def rotation_exp(w) -> np.ndarray:
    """exp([w]×): the rotation by |w| about w/|w| (Rodrigues)."""
    w = np.asarray(w, dtype=float)
    th = float(np.linalg.norm(w))
    if th < 1e-12:
        return np.eye(3) + skew(w)
    K = skew(w / th)
    return np.eye(3) + math.sin(th) * K + (1.0 - math.cos(th)) * K @ K


def rotation_from_vector(w) -> RotationMatrix:
    """exp([w]×) as Drake's ``RotationMatrix`` (through ``AngleAxis``): the rotation by |w| rad
    about w/|w| (the identity for w = 0)."""
    w = np.asarray(w, dtype=float)
    angle = math.sqrt(float(w @ w))
    return RotationMatrix() if angle == 0.0 else RotationMatrix(AngleAxis(angle, w / angle))


def rpy_matrix(rpy_deg) -> np.ndarray:
    """Drake's RollPitchYaw (R = Rz·Ry·Rx) of angles in degrees, as a 3 × 3 matrix."""
    return RollPitchYaw(np.radians(np.asarray(rpy_deg, dtype=float))).ToRotationMatrix().matrix()


class SpinningOrientation:
    """R_r(t) = exp([ω] t) R0: the object frame at t = 0 (roll-pitch-yaw, degrees) turning at a
    constant world-frame angular velocity ω (deg/s); ω̇_r = 0."""

    def __init__(self, rpy_deg, rate_deg_s=(0.0, 0.0, 0.0)):
        self.R0 = rpy_matrix(rpy_deg)
        self.omega = np.radians(np.asarray(rate_deg_s, dtype=float))
        self._fixed = list(self.R0.ravel()) + [0.0] * 6 if not self.omega.any() else None

    def values(self, t: float) -> list:
        """[R_r row-major, ω_r, ω̇_r] (15 plain floats) at time t."""
        if self._fixed is not None:
            return list(self._fixed)
        R = rotation_exp(self.omega * t) @ self.R0
        return R.ravel().tolist() + self.omega.tolist() + [0.0, 0.0, 0.0]


class SlerpOrientation:
    """R_r(t) through sampled orientations (roll-pitch-yaw, degrees), Drake's
    ``PiecewiseQuaternionSlerp`` between samples; held (ω_r = 0) outside them."""

    def __init__(self, time, rpy_deg):
        rotations = [Quaternion(RotationMatrix(rpy_matrix(r)).ToQuaternion().wxyz()) for r in rpy_deg]
        self.trajectory = PiecewiseQuaternionSlerp(list(map(float, time)), rotations)
        self._t0, self._t1 = float(time[0]), float(time[-1])

    def values(self, t: float) -> list:
        """[R_r row-major, ω_r, ω̇_r] (15 plain floats) at time t."""
        tc = min(max(t, self._t0), self._t1)
        R = RotationMatrix(self.trajectory.orientation(tc)).matrix()
        if t < self._t0 or t > self._t1:
            return R.ravel().tolist() + [0.0] * 6
        w = self.trajectory.angular_velocity(tc)
        return R.ravel().tolist() + list(map(float, w)) + [0.0, 0.0, 0.0]


class OrientedTarget:
    """A position target (``values``/``evaluate`` unchanged) with an orientation
    (``rotation_values(t)``: [R_r, ω_r, ω̇_r])."""

    def __init__(self, position, orientation):
        self.position = position
        self.orientation = orientation

    def values(self, t: float) -> list:
        values = getattr(self.position, "values", None)
        return values(t) if values is not None else self.position.evaluate(t).tolist()

    def evaluate(self, t: float) -> np.ndarray:
        return self.position.evaluate(t)

    def rotation_values(self, t: float) -> list:
        return self.orientation.values(t)


def target_rotation_values(target, t: float) -> list:
    """[R_r, ω_r, ω̇_r] (15 plain floats) of a target at t; an unturned, fixed frame if it has
    no orientation."""
    values = getattr(target, "rotation_values", None)
    return values(t) if values is not None else list(IDENTITY_ROTATION)


def active_rotation_values(schedule, targets, t: float) -> list:
    """``target_rotation_values`` of the target of the segment active at t (the first before)."""
    return target_rotation_values(targets[max(schedule.active(t), 0)], t)


def _cross(u, v) -> list:
    """u × v of two 3-sequences of floats (np.cross costs ~60 µs a call; this ~1 µs)."""
    return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]


def top_down_reference(rot_r, tool_yaw: float) -> list:
    """[R_r, ω_r, ω̇_r] of the top-down grasp of an object with orientation ``rot_r`` (15):
    R_r = Rz(ψ)·Rx(π), ψ the angle of the object's x axis in the horizontal plane modulo π,
    on the branch nearest ``tool_yaw``; ω_r = [0, 0, ψ̇], ω̇_r = [0, 0, ψ̈]."""
    r = [float(v) for v in rot_r]
    a = (r[0], r[3], r[6])  # the object's x axis: R's first column
    w, wd = r[9:12], r[12:15]
    ad = _cross(w, a)
    add = [p + q for p, q in zip(_cross(wd, a), _cross(w, ad))]
    h = a[0] * a[0] + a[1] * a[1]
    psi = math.atan2(a[1], a[0])
    psi += math.pi * round((tool_yaw - psi) / math.pi)
    num = a[0] * ad[1] - a[1] * ad[0]
    psi_d = num / h
    psi_dd = ((a[0] * add[1] - a[1] * add[0]) * h - num * 2.0 * (a[0] * ad[0] + a[1] * ad[1])) / (h * h)
    c, s = math.cos(psi), math.sin(psi)
    Rr = [c, s, 0.0, s, -c, 0.0, 0.0, 0.0, -1.0]  # Rz(ψ)·Rx(π), row-major
    return Rr + [0.0, 0.0, psi_d, 0.0, 0.0, psi_dd]


def tool_yaw(R) -> float:
    """The angle of the tool's x axis in the horizontal plane (R row-major or 3 × 3)."""
    R = np.asarray(R, dtype=float).reshape(3, 3)
    return math.atan2(R[1, 0], R[0, 0])


def rotation_error(R, omega, rot_r) -> tuple:
    """(e_R, ė_R) as lists: log(R R_rᵀ)^∨ and ω − R R_rᵀ ω_r (R, R_r row-major or 3 × 3)."""
    Re = np.asarray(R, dtype=float).reshape(3, 3) @ np.asarray(rot_r[0:9], dtype=float).reshape(3, 3).T
    e = rotation_log(Re)
    edot = np.asarray(omega, dtype=float) - Re @ np.asarray(rot_r[9:12], dtype=float)
    return e.tolist(), edot.tolist()


def orientation_error_angle(task: str, R, rot_r) -> float:
    """The angle (rad) between the tool's orientation R and what the task asks for: the
    object's orientation (``pose``), or the nearer of the two top-down grasps (``top_down``)."""
    ref = top_down_reference(rot_r, tool_yaw(R)) if task == "top_down" else rot_r
    return rotation_angle(np.asarray(R, dtype=float).reshape(3, 3), np.asarray(ref[0:9]).reshape(3, 3))


def has_orientation(target) -> bool:
    """Whether a target carries an orientation (``OrientedTarget``)."""
    return getattr(target, "rotation_values", None) is not None


class ObjectRotations(LeafSystem):
    """Output port ``object_rotations`` (9 × number of targets, time only): every target's true
    orientation R_r(t), row-major (an unturned frame for a target without one) — what a camera
    that measures orientations looks at."""

    def __init__(self, targets):
        super().__init__()
        self._targets = tuple(targets)
        self.DeclareVectorOutputPort(
            "object_rotations", 9 * len(self._targets),
            lambda c, o: o.SetFromVector([v for tg in self._targets
                                          for v in target_rotation_values(tg, c.get_time())[0:9]]),
            prerequisites_of_calc={self.time_ticket()})
