"""Orientation for the interceptor's ``pose`` and ``top_down`` tasks (issue 19).

A target may carry the object frame's orientation R_r(t) with its world-frame angular
velocity ω_r and acceleration ω̇_r (``signals.TARGET_ROTATION``: 15 values).  The task error
stacks the position error and the rotation error, scaled by ``rot_scale`` c (m per rad;
``systems.task.error``):

    e = [x − x_r;  c e_R],   e_R = log(R R_rᵀ)^∨         (world frame, shorter rotation)
    ė = [ẋ − ẋ_r;  c ė_R],   ė_R = ω − R R_rᵀ ω_r        (the error rotation's angular velocity)
    J = [J_v;  c J_ω]                                     (ė = J q̇ − [ẋ_r; c R R_rᵀ ω_r])

Since d/dt e_R = J_l⁻¹(e_R) ė_R and J_l⁻¹(e) e = e, the ideal surface ė + α e = 0 keeps the
paper's decay law e(t) = e(t0)((ξ + δ)/(ξ(t0) + δ))^α0 for the rotation too, about a fixed
axis.  ``top_down`` replaces R_r by Rz(ψ)·Rx(π): approach axis (z) straight down, ψ the
object's horizontal x-axis angle modulo 180° on the branch nearest the tool's current yaw.
Kinematics only: still model-free.

Each equation is one compiled function (numba: ``rotation_log_of``, ``rotation_exp_of``,
``rotation_error_of``, ``top_down_of``, ``rotation_row``) that the fused interceptor's kernel,
the blocks and the metrics call alike; the plain-Python names (``rotation_log``,
``rotation_error``, ``top_down_reference``, …) wrap them for lists and arrays.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydrake.common.eigen_geometry import AngleAxis, Quaternion
from pydrake.math import RollPitchYaw, RotationMatrix
from pydrake.systems.framework import LeafSystem
from pydrake.trajectories import PiecewiseQuaternionSlerp

from ptint_drake.systems.task.chain import axis_rotation
from ptint_drake.systems.task.signals import IDENTITY_ROTATION
from ptint_drake.systems.task.views import copy_into

# A compiled orientation: [R0 (row-major, 9), ω (3)] (``SpinningOrientation.compiled``).
ROTATION_WIDTH = 12
IDENTITY_ROW = np.array(IDENTITY_ROTATION[:12])


@njit(cache=True)
def rotation_log_of(Re, out) -> None:
    """``out[:3]`` ← log(Re)^∨ of a 3 × 3 rotation: axis × angle of the shorter rotation, angle in
    [0, π].  Through the unit quaternion (w ≥ 0) taken from the largest of 1 + trace and the
    diagonal's 1 + 2 Rᵢᵢ − trace (the well-conditioned branch), angle = 2 atan2(|v|, w)."""
    m00, m01, m02 = Re[0, 0], Re[0, 1], Re[0, 2]
    m10, m11, m12 = Re[1, 0], Re[1, 1], Re[1, 2]
    m20, m21, m22 = Re[2, 0], Re[2, 1], Re[2, 2]
    tr = m00 + m11 + m22
    if tr >= m00 and tr >= m11 and tr >= m22:
        w, x, y, z = 1.0 + tr, m21 - m12, m02 - m20, m10 - m01
    elif m00 >= m11 and m00 >= m22:
        w, x, y, z = m21 - m12, 1.0 - (tr - 2.0 * m00), m01 + m10, m02 + m20
    elif m11 >= m22:
        w, x, y, z = m02 - m20, m01 + m10, 1.0 - (tr - 2.0 * m11), m12 + m21
    else:
        w, x, y, z = m10 - m01, m02 + m20, m12 + m21, 1.0 - (tr - 2.0 * m22)
    scale = (-1.0 if w < 0.0 else 1.0) / math.sqrt(w * w + x * x + y * y + z * z)
    w, x, y, z = w * scale, x * scale, y * scale, z * scale
    n = math.sqrt(x * x + y * y + z * z)
    f = 2.0 / w if n < 1e-12 else 2.0 * math.atan2(n, w) / n
    out[0], out[1], out[2] = f * x, f * y, f * z


def rotation_log(Re: np.ndarray) -> np.ndarray:
    """log(Re)^∨ (3): axis × angle of the shorter rotation, angle in [0, π] (``rotation_log_of``)."""
    out = np.empty(3)
    rotation_log_of(np.ascontiguousarray(Re, dtype=float).reshape(3, 3), out)
    return out


def rotation_angle(R: np.ndarray, R_r: np.ndarray) -> float:
    """The full angle (rad) of R_rᵀ R: how far orientation R is from R_r."""
    return float(np.linalg.norm(rotation_log(np.asarray(R) @ np.asarray(R_r).T)))


@njit(cache=True)
def rotation_exp_of(w, out) -> None:
    """``out`` ← exp([w]×) (3 × 3): the rotation by |w| about w/|w| (Rodrigues,
    ``chain``'s axis rotation); I + [w]× below |w| = 1e-12."""
    th = math.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2])
    if th < 1e-12:
        out[0, 0], out[0, 1], out[0, 2] = 1.0, -w[2], w[1]
        out[1, 0], out[1, 1], out[1, 2] = w[2], 1.0, -w[0]
        out[2, 0], out[2, 1], out[2, 2] = -w[1], w[0], 1.0
        return
    axis_rotation(np.array((w[0] / th, w[1] / th, w[2] / th)), th, out)


def rotation_exp(w) -> np.ndarray:
    """exp([w]×): the rotation by |w| about w/|w| (``rotation_exp_of``)."""
    out = np.empty((3, 3))
    rotation_exp_of(np.asarray(w, dtype=float), out)
    return out


def rotation_from_vector(w) -> RotationMatrix:
    """exp([w]×) as Drake's ``RotationMatrix`` (through ``AngleAxis``): the rotation by |w| rad
    about w/|w| (the identity for w = 0)."""
    w = np.asarray(w, dtype=float)
    angle = math.sqrt(float(w @ w))
    return RotationMatrix() if angle == 0.0 else RotationMatrix(AngleAxis(angle, w / angle))


def rpy_matrix(rpy_deg) -> np.ndarray:
    """Drake's RollPitchYaw (R = Rz·Ry·Rx) of angles in degrees, as a 3 × 3 matrix."""
    return RollPitchYaw(np.radians(np.asarray(rpy_deg, dtype=float))).ToRotationMatrix().matrix()


@njit(cache=True)
def rotation_row(c, t: float, out) -> None:
    """``out[:15]`` ← [R_r (row-major), ω_r, ω̇_r] at time t of the compiled orientation
    c = [R0, ω] (``ROTATION_WIDTH``): R_r = exp([ω] t) R0, ω_r = ω, ω̇_r = 0."""
    if c[9] == 0.0 and c[10] == 0.0 and c[11] == 0.0:
        copy_into(out, 0, c[0:9])
    else:
        E = np.empty((3, 3))
        rotation_exp_of(np.array((c[9] * t, c[10] * t, c[11] * t)), E)
        for i in range(3):
            for j in range(3):
                out[3 * i + j] = E[i, 0] * c[j] + E[i, 1] * c[3 + j] + E[i, 2] * c[6 + j]
    copy_into(out, 9, c[9:12])
    out[12:15] = 0.0


class SpinningOrientation:
    """R_r(t) = exp([ω] t) R0: the object frame at t = 0 (roll-pitch-yaw, degrees) turning at a
    constant world-frame angular velocity ω (deg/s); ω̇_r = 0 (``rotation_row``)."""

    def __init__(self, rpy_deg, rate_deg_s=(0.0, 0.0, 0.0)):
        self.R0 = rpy_matrix(rpy_deg)
        self.omega = np.radians(np.asarray(rate_deg_s, dtype=float))
        self.compiled = np.concatenate([self.R0.ravel(), self.omega])

    def values(self, t: float) -> list:
        """[R_r row-major, ω_r, ω̇_r] (15 plain floats) at time t."""
        out = np.empty(15)
        rotation_row(self.compiled, float(t), out)
        return out.tolist()


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
    """A position target (``values``/``evaluate`` and its ``compiled`` row unchanged) with an
    orientation (``rotation_values(t)``: [R_r, ω_r, ω̇_r]; ``compiled_rotation``: its
    ``rotation_row`` row, None for a sampled one)."""

    def __init__(self, position, orientation):
        self.position = position
        self.orientation = orientation
        self.compiled = getattr(position, "compiled", None)
        self.compiled_rotation = getattr(orientation, "compiled", None)

    def values(self, t: float) -> list:
        values = getattr(self.position, "values", None)
        return values(t) if values is not None else self.position.evaluate(t).tolist()

    def evaluate(self, t: float) -> np.ndarray:
        return self.position.evaluate(t)

    def rotation_values(self, t: float) -> list:
        return self.orientation.values(t)


def compiled_rotations(targets):
    """The targets' orientations as ``rotation_row`` rows (count × ``ROTATION_WIDTH``; an unturned,
    fixed frame for a target without one), or None when one is sampled (evaluated in Python)."""
    rows = [getattr(tg, "compiled_rotation", None) if has_orientation(tg) else IDENTITY_ROW
            for tg in targets]
    return None if any(r is None for r in rows) else np.array(rows)


def target_rotation_values(target, t: float) -> list:
    """[R_r, ω_r, ω̇_r] (15 plain floats) of a target at t; an unturned, fixed frame if it has
    no orientation."""
    values = getattr(target, "rotation_values", None)
    return values(t) if values is not None else list(IDENTITY_ROTATION)


def active_rotation_values(schedule, targets, t: float) -> list:
    """``target_rotation_values`` of the target of the segment active at t (the first before)."""
    return target_rotation_values(targets[max(schedule.active(t), 0)], t)


@njit(cache=True)
def tool_yaw_of(R) -> float:
    """The angle of the tool's x axis in the horizontal plane (R row-major, 9)."""
    return math.atan2(R[3], R[0])


@njit(cache=True)
def top_down_of(rot_r, tool_yaw: float, out) -> None:
    """``out[:15]`` ← [R_r, ω_r, ω̇_r] of the top-down grasp of an object with orientation
    ``rot_r`` (15): R_r = Rz(ψ)·Rx(π), ψ the angle of the object's x axis a (R's first column) in
    the horizontal plane modulo π, on the branch nearest ``tool_yaw``; ω_r = [0, 0, ψ̇],
    ω̇_r = [0, 0, ψ̈] with ȧ = ω × a, ä = ω̇ × a + ω × ȧ."""
    a0, a1, a2 = rot_r[0], rot_r[3], rot_r[6]
    w0, w1, w2 = rot_r[9], rot_r[10], rot_r[11]
    d0, d1, d2 = rot_r[12], rot_r[13], rot_r[14]
    ad0, ad1, ad2 = w1 * a2 - w2 * a1, w2 * a0 - w0 * a2, w0 * a1 - w1 * a0
    add0 = (d1 * a2 - d2 * a1) + (w1 * ad2 - w2 * ad1)
    add1 = (d2 * a0 - d0 * a2) + (w2 * ad0 - w0 * ad2)
    h = a0 * a0 + a1 * a1
    psi = math.atan2(a1, a0)
    psi += math.pi * np.rint((tool_yaw - psi) / math.pi)
    num = a0 * ad1 - a1 * ad0
    c, s = math.cos(psi), math.sin(psi)
    out[0], out[1], out[2], out[3], out[4] = c, s, 0.0, s, -c  # Rz(ψ)·Rx(π), row-major
    out[5], out[6], out[7], out[8] = 0.0, 0.0, 0.0, -1.0
    out[9], out[10], out[11], out[12], out[13] = 0.0, 0.0, num / h, 0.0, 0.0
    out[14] = ((a0 * add1 - a1 * add0) * h - num * 2.0 * (a0 * ad0 + a1 * ad1)) / (h * h)


@njit(cache=True)
def rotation_error_of(R, omega, rot_r, out) -> None:
    """``out[:6]`` ← [e_R; ė_R] = [log(R R_rᵀ)^∨; ω − R R_rᵀ ω_r] (R, R_r row-major, 9)."""
    Re = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            a, b = 3 * i, 3 * j
            Re[i, j] = R[a] * rot_r[b] + R[a + 1] * rot_r[b + 1] + R[a + 2] * rot_r[b + 2]
    rotation_log_of(Re, out)
    for i in range(3):
        out[3 + i] = omega[i] - (Re[i, 0] * rot_r[9] + Re[i, 1] * rot_r[10] + Re[i, 2] * rot_r[11])


def _flat(a) -> np.ndarray:
    """A sequence (or 3 × 3 array) as a contiguous float vector, for the compiled kernels."""
    return np.ascontiguousarray(a, dtype=float).reshape(-1)


def top_down_reference(rot_r, tool_yaw: float) -> list:
    """[R_r, ω_r, ω̇_r] (15 plain floats) of the top-down grasp of an object with orientation
    ``rot_r`` (``top_down_of``)."""
    out = np.empty(15)
    top_down_of(_flat(rot_r), float(tool_yaw), out)
    return out.tolist()


def tool_yaw(R) -> float:
    """The angle of the tool's x axis in the horizontal plane (R row-major or 3 × 3)."""
    return tool_yaw_of(_flat(R))


def rotation_error(R, omega, rot_r) -> tuple:
    """(e_R, ė_R) as lists: log(R R_rᵀ)^∨ and ω − R R_rᵀ ω_r (R, R_r row-major or 3 × 3;
    ``rotation_error_of``)."""
    out = np.empty(6)
    rotation_error_of(_flat(R), _flat(omega), _flat(rot_r), out)
    return out[:3].tolist(), out[3:].tolist()


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
