"""A serial kinematic chain extracted from a MultibodyPlant at build time, compiled (numba).

For a frame E on a body reached from the world (or a welded base) through revolute and
prismatic joints only, the pose of E and its Jacobians are a product of fixed transforms and
joint motions (paper eq. 5: x = f(q), ẋ = J(q) q̇):

    X_WE = X_0 · M_1(q_1) · X_1 · M_2(q_2) · … · M_n(q_n) · X_n

X_0 … X_n fold every fixed transform between two moving joints (a joint's frame on its parent
body, the inverse of its frame on the child body, weld joints, E's pose in its body); M_k is a
rotation about the joint's axis (revolute) or a translation along it (prismatic), both in the
joint's frame F.  Column k of the Jacobians (v_k = q̇_k for these joints): revolute
J_ω = a_k, J_v = a_k × (x − o_k); prismatic J_ω = 0, J_v = a_k (a_k the axis in the world,
o_k the joint's origin).  ``KinematicChain.of`` returns None for anything else (a floating
body, a ball or planar joint, a frame not reached from the world), and ``FrameKinematics``
then asks the plant.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from numba import njit

REVOLUTE, PRISMATIC = 0, 1


@njit(cache=True, inline="always")
def _then(R, p, R2, p2, tmp):
    """(R, p) ← (R R2, p + R p2) in place: the transform (R, p) followed by (R2, p2)."""
    for i in range(3):
        p[i] += R[i, 0] * p2[0] + R[i, 1] * p2[1] + R[i, 2] * p2[2]
        for j in range(3):
            tmp[j] = R[i, 0] * R2[0, j] + R[i, 1] * R2[1, j] + R[i, 2] * R2[2, j]
        for j in range(3):
            R[i, j] = tmp[j]


@njit(cache=True, inline="always")
def axis_rotation(a, angle, out):
    """``out`` ← the rotation by ``angle`` (rad) about the unit axis a (Rodrigues' formula)."""
    c, s = np.cos(angle), np.sin(angle)
    t = 1.0 - c
    x, y, z = a[0], a[1], a[2]
    out[0, 0], out[0, 1], out[0, 2] = c + t * x * x, t * x * y - s * z, t * x * z + s * y
    out[1, 0], out[1, 1], out[1, 2] = t * x * y + s * z, c + t * y * y, t * y * z - s * x
    out[2, 0], out[2, 1], out[2, 2] = t * x * z - s * y, t * y * z + s * x, c + t * z * z


@njit(cache=True)
def chain_kinematics(q, joints, geometry, nv):
    """(x, R, J_v, J_ω) of the chain's end frame at the plant's positions q: its origin in the
    world (3), orientation (3 × 3) and translational / rotational Jacobians (3 × nv).

    ``joints`` (3 × n, floats): each joint's kind (``REVOLUTE`` or ``PRISMATIC``), position in
    the plant's q and velocity in its v; ``geometry`` (n + 1, 5, 3): X_0 … X_n as [R; pᵀ] with
    row 4 the next joint's unit axis in its frame F (``KinematicChain``; ``chain_kinematics_into``
    in new arrays, called with the argument types the fused kernel passes: one compiled version)."""
    n = joints.shape[1]
    x, R, J_v, J_w = np.empty(3), np.empty((3, 3)), np.empty((3, nv)), np.empty((3, nv))
    chain_kinematics_into(q, joints[0], joints[1], joints[2], geometry[:, :4], geometry[:-1, 4], x, R, J_v,
                          J_w, np.empty((2 * n + 5, 3)))
    return x, R, J_v, J_w


@njit(cache=True)
def chain_kinematics_into(q, kinds, q_index, v_index, fixed, axes, x, R, J_v, J_w, work) -> None:
    """x (3), R (3 × 3), J_v, J_ω (3 × nv) ← ``chain_kinematics`` without allocating: ``work``
    is a scratch block of ≥ 2n + 5 rows of 3 (n joints).  ``kinds``, ``q_index`` and ``v_index``
    may be integer arrays or whole numbers held as floats (a packed float array)."""
    n = len(kinds)
    p = x
    for i in range(3):
        p[i] = fixed[0, 3, i]
        for j in range(3):
            R[i, j] = fixed[0, i, j]
    # axes and origins in the world, a rotation, a row, a zero translation
    axes_w, origins, M, tmp = work[:n], work[n:2 * n], work[2 * n:2 * n + 3], work[2 * n + 3]
    zero = work[2 * n + 4]
    zero[:] = 0.0
    for k in range(n):
        a = axes[k]
        for i in range(3):
            axes_w[k, i] = R[i, 0] * a[0] + R[i, 1] * a[1] + R[i, 2] * a[2]
            origins[k, i] = p[i]
        if kinds[k] == REVOLUTE:
            axis_rotation(a, q[int(q_index[k])], M)
            _then(R, p, M, zero, tmp)
        else:
            for i in range(3):
                p[i] += q[int(q_index[k])] * axes_w[k, i]
        _then(R, p, fixed[k + 1, :3], fixed[k + 1, 3], tmp)
    J_v[:] = 0.0
    J_w[:] = 0.0
    for k in range(n):
        a, col = axes_w[k], int(v_index[k])
        if kinds[k] == REVOLUTE:
            r0, r1, r2 = p[0] - origins[k, 0], p[1] - origins[k, 1], p[2] - origins[k, 2]
            J_v[0, col] += a[1] * r2 - a[2] * r1
            J_v[1, col] += a[2] * r0 - a[0] * r2
            J_v[2, col] += a[0] * r1 - a[1] * r0
            for i in range(3):
                J_w[i, col] += a[i]
        else:
            for i in range(3):
                J_v[i, col] += a[i]


def _pose(X) -> np.ndarray:
    """A RigidTransform as the 4 × 3 block [R; pᵀ]."""
    return np.vstack([X.rotation().matrix(), X.translation()])


class KinematicChain:
    """The joints from the world to one frame, as arrays for ``chain_kinematics``: ``joints``
    [kinds; q index; v index] (3 × n, whole numbers as floats) and ``geometry``, the fixed
    transforms X_0 … X_n as [R; pᵀ] with row 4 = the next joint's axis ((n + 1) × 5 × 3)."""

    def __init__(self, kinds, q_index, v_index, fixed, axes, nv: int):
        self.kinds = np.asarray(kinds, dtype=np.int64)
        self.q_index = np.asarray(q_index, dtype=np.int64)
        self.v_index = np.asarray(v_index, dtype=np.int64)
        self.fixed = np.ascontiguousarray(fixed, dtype=float)
        self.axes = np.ascontiguousarray(axes, dtype=float).reshape(-1, 3)
        self.nv = int(nv)
        self.joints = np.array([self.kinds, self.q_index, self.v_index], dtype=float).reshape(3, -1)
        self.geometry = np.zeros((len(self.fixed), 5, 3))
        self.geometry[:, :4] = self.fixed
        self.geometry[:-1, 4] = self.axes

    @classmethod
    def of(cls, plant, frame) -> Optional["KinematicChain"]:
        """The chain of ``frame`` on the finalized ``plant``, or None when it is not a serial chain
        of revolute, prismatic and weld joints from the world."""
        inboard = {}
        for index in plant.GetJointIndices():
            joint = plant.get_joint(index)
            inboard[joint.child_body().index()] = joint
        world = plant.world_body().index()
        body = frame.body()
        tail = frame.GetFixedPoseInBodyFrame()  # X_BE
        moving = []  # (joint, X from its frame M to the next joint's frame F), outermost first
        while body.index() != world:
            joint = inboard.get(body.index())
            kind = None if joint is None else joint.type_name()
            if kind not in ("revolute", "prismatic", "weld"):
                return None
            X_MB = joint.frame_on_child().GetFixedPoseInBodyFrame().inverse()
            tail = X_MB.multiply(tail)
            if kind == "weld":
                tail = joint.X_FM().multiply(tail)
            else:
                moving.append((joint, tail))
                tail = None
            X_PF = joint.frame_on_parent().GetFixedPoseInBodyFrame()
            tail = X_PF if tail is None else X_PF.multiply(tail)
            body = joint.parent_body()
        moving.reverse()
        fixed = [_pose(tail)] + [_pose(X) for _, X in moving]
        kinds, q_index, v_index, axes = [], [], [], []
        for joint, _ in moving:
            revolute = joint.type_name() == "revolute"
            kinds.append(REVOLUTE if revolute else PRISMATIC)
            q_index.append(joint.position_start())
            v_index.append(joint.velocity_start())
            axes.append(joint.revolute_axis() if revolute else joint.translation_axis())
        return cls(kinds, q_index, v_index, np.array(fixed), np.array(axes), plant.num_velocities())

    def evaluate(self, q) -> tuple:
        """(x, R, J_v, J_ω) at the plant's positions q (``chain_kinematics``)."""
        return chain_kinematics(np.asarray(q, dtype=float), self.joints, self.geometry, self.nv)

