"""The task error of the interceptor (paper eq. 11, generalized by issue 19): which error
the sliding surface drives to zero, and the Jacobian that maps joint speeds onto its rate.

- ``position`` (the paper's, 3-D): e = x − x_r, ė = ẋ − ẋ_r, J = J_v;
- ``pose`` (6-D, ≥ 6 joints): e = [x − x_r; c e_R], e_R = log(R R_rᵀ)^∨,
  ė = [ẋ − ẋ_r; c (ω − R R_rᵀ ω_r)], J = [J_v; c J_ω];
- ``top_down`` (6-D, ≥ 5 joints): the same with R_r = Rz(ψ)·Rx(π) (``orientation``), solved
  in the least-squares sense (rank 5 on a 5-joint wrist).

c = ``rot_scale`` (m per rad) says how a radian of orientation error weighs against a metre.
``task_error_of`` is the one implementation (compiled, numba): the fused interceptor's kernel
calls it, and ``task_error`` (the blocks) wraps it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ptint_drake.systems.task.orientation import (rotation_error_of, tool_yaw, tool_yaw_of, top_down_of,
                                                  top_down_reference)

TASKS = ("position", "pose", "top_down")  # their codes in compiled code: the index
POSITION, POSE, TOP_DOWN = 0, 1, 2
TASK_MIN_JOINTS = {"position": 3, "pose": 6, "top_down": 5}
TASK_DIM = {"position": 3, "pose": 6, "top_down": 6}
_NO_ROTATION = np.zeros(15)


@njit(cache=True)
def task_error_of(task: int, rot_scale: float, x, xdot, x_r, xdot_r, R, omega, rot_r, out) -> None:
    """``out[:2n]`` ← [e; ė] of the task with code ``task`` (the index in ``TASKS``; n = 3 for
    ``position``, 6 otherwise): see the module docstring.  R (row-major, 9), ω: the tool's
    orientation and angular velocity; rot_r: the object's [R_r, ω_r, ω̇_r] (15); the three are
    not read for ``position``."""
    n = 3 if task == POSITION else 6
    for i in range(3):
        out[i], out[n + i] = x[i] - x_r[i], xdot[i] - xdot_r[i]
    if task == POSITION:
        return
    rotation = np.empty(6)
    if task == TOP_DOWN:
        reference = np.empty(15)
        top_down_of(rot_r, tool_yaw_of(R), reference)
        rotation_error_of(R, omega, reference, rotation)
    else:
        rotation_error_of(R, omega, rot_r, rotation)
    for i in range(3):
        out[3 + i], out[9 + i] = rot_scale * rotation[i], rot_scale * rotation[3 + i]


def _flat(a) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=float).reshape(-1)


def task_reference(task: str, rot_r, R) -> list:
    """[R_r, ω_r, ω̇_r] the task tracks: the object's own (``pose``) or its top-down grasp
    (``top_down``, the branch nearest the tool's yaw; R the tool's orientation)."""
    return top_down_reference(rot_r, tool_yaw(R)) if task == "top_down" else list(rot_r)


def task_error(task: str, rot_scale: float, x, xdot, x_r, xdot_r, R=None, omega=None,
               rot_r=None) -> tuple:
    """(e, ė) of the task as arrays (3 for ``position``, 6 otherwise; ``task_error_of``).
    R (3 × 3 or row-major), ω: the tool's orientation and angular velocity; rot_r: the object's
    [R_r, ω_r, ω̇_r]; none of them needed for ``position``."""
    n = TASK_DIM[task]
    out = np.empty(2 * n)
    rotation = [_NO_ROTATION] * 3 if task == "position" else [_flat(R), _flat(omega), _flat(rot_r)]
    task_error_of(TASKS.index(task), float(rot_scale), _flat(x), _flat(xdot), _flat(x_r), _flat(xdot_r),
                  *rotation, out)
    return out[:n], out[n:]


@njit(cache=True)
def task_jacobian_of(J_v, J_w, rot_scale, J):
    """J ← the Jacobian of the stacked task error: J_v (3 × nv) for a position task (J 3 × nv),
    [J_v; c J_ω] for a task with orientation (J 6 × nv, c = ``rot_scale``)."""
    n, nv = J.shape
    for k in range(nv):
        for i in range(3):
            J[i, k] = J_v[i, k]
            if n == 6:
                J[3 + i, k] = rot_scale * J_w[i, k]


def task_jacobian(J_v: np.ndarray, J_w: np.ndarray, rot_scale: float) -> np.ndarray:
    """[J_v; c J_ω] (6 × nv): the Jacobian of the stacked task error (``task_jacobian_of``)."""
    J = np.empty((6, np.shape(J_v)[1]))
    task_jacobian_of(np.ascontiguousarray(J_v, dtype=float), np.ascontiguousarray(J_w, dtype=float),
                     float(rot_scale), J)
    return J
