"""The task error of the interceptor (paper eq. 11, generalized by issue 19): which error
the sliding surface drives to zero, and the Jacobian that maps joint speeds onto its rate.

- ``position`` (the paper's, 3-D): e = x − x_r, ė = ẋ − ẋ_r, J = J_v;
- ``pose`` (6-D, ≥ 6 joints): e = [x − x_r; c e_R], e_R = log(R R_rᵀ)^∨,
  ė = [ẋ − ẋ_r; c (ω − R R_rᵀ ω_r)], J = [J_v; c J_ω];
- ``top_down`` (6-D, ≥ 5 joints): the same with R_r = Rz(ψ)·Rx(π) (``orientation``), solved
  in the least-squares sense (rank 5 on a 5-joint wrist).

c = ``rot_scale`` (m per rad) says how a radian of orientation error weighs against a metre.
"""

from __future__ import annotations

import numpy as np

from ptint_drake.systems.orientation import rotation_error, tool_yaw, top_down_reference

TASKS = ("position", "pose", "top_down")
TASK_MIN_JOINTS = {"position": 3, "pose": 6, "top_down": 5}
TASK_DIM = {"position": 3, "pose": 6, "top_down": 6}


def position_error(x, xdot, x_r, xdot_r) -> tuple:
    """(e, ė) = (x − x_r, ẋ − ẋ_r) of 3 plain floats each (paper eq. 11)."""
    x0, x1, x2 = x
    r0, r1, r2 = x_r
    e = [x0 - r0, x1 - r1, x2 - r2]
    x0, x1, x2 = xdot
    r0, r1, r2 = xdot_r
    return e, [x0 - r0, x1 - r1, x2 - r2]


def task_reference(task: str, rot_r, R) -> list:
    """[R_r, ω_r, ω̇_r] the task tracks: the object's own (``pose``) or its top-down grasp
    (``top_down``, the branch nearest the tool's yaw; R the tool's orientation)."""
    return top_down_reference(rot_r, tool_yaw(R)) if task == "top_down" else list(rot_r)


def task_error(task: str, rot_scale: float, x, xdot, x_r, xdot_r, R=None, omega=None,
               rot_r=None) -> tuple:
    """(e, ė) of the task as lists of plain floats (3 for ``position``, 6 otherwise): see the
    module docstring.  R (3 × 3 or row-major), ω: the tool's orientation and angular velocity;
    rot_r: the object's [R_r, ω_r, ω̇_r]."""
    e, edot = position_error(x, xdot, x_r, xdot_r)
    if task == "position":
        return e, edot
    e_R, edot_R = rotation_error(R, omega, task_reference(task, rot_r, R))
    c = rot_scale
    return e + [c * a for a in e_R], edot + [c * a for a in edot_R]


def task_jacobian(J_v: np.ndarray, J_w: np.ndarray, rot_scale: float) -> np.ndarray:
    """[J_v; c J_ω] (6 × nv): the Jacobian of the stacked task error."""
    return np.vstack([J_v, rot_scale * J_w])
