"""Second-order sliding-mode controller τ = −K J⁺(q) s_x  (SPEC section 2.3, paper eq. 18).

Model-free: the only robot knowledge it takes is the Jacobian J (kinematics).
For a square J the pseudoinverse product J⁺ s_x is a linear solve; for a
redundant arm (more joints than 3) it is the minimum-norm solution
Jᵀ (J Jᵀ)⁻¹ s_x.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.systems.task import TASK_DIM


def solve3(A: list, b: list) -> list:
    """A⁻¹ b for a 3 × 3 A (3 rows of plain floats) and b (3 plain floats) by Cramer's rule
    (numpy's solve costs ~15 µs here); a least-squares solution when A is numerically singular."""
    (a, b_, c), (d, e, f), (g, h, i) = A
    co0, co1, co2 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * co0 + b_ * co1 + c * co2
    scale = max(abs(a), abs(b_), abs(c), abs(d), abs(e), abs(f), abs(g), abs(h), abs(i)) or 1.0
    if abs(det) <= 1e-12 * scale**3:
        return np.linalg.lstsq(np.array(A), np.array(b), rcond=None)[0].tolist()
    x, y, z = b
    return [(co0 * x + (c * h - b_ * i) * y + (b_ * f - c * e) * z) / det,
            (co1 * x + (a * i - c * g) * y + (c * d - a * f) * z) / det,
            (co2 * x + (b_ * g - a * h) * y + (a * e - b_ * d) * z) / det]


def pinv_apply(J, b, damping: float = 0.0) -> list:
    """J⁺ b for a 3 × nv J and a 3-vector b (lists of plain floats, the fast form, or arrays),
    as a list: a solve for square J, the minimum-norm solution Jᵀ(JJᵀ)⁻¹ b otherwise.
    For a task of another dimension (6 rows: position and orientation, ``systems.task``) it is
    the minimum-norm least-squares solution (``lstsq``): J⁻¹ b for a square J, the least-squares
    fit for fewer joints than rows (a 5-joint wrist), the minimum-norm one for more.

    With ``damping`` λ > 0 (m/rad), J⁺ is the damped pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹, which
    stays bounded through singular configurations at the cost of a small bias near them.
    """
    if len(J) != 3:
        Ja = np.asarray(J, dtype=float)
        if damping > 0.0:
            return (Ja.T @ np.linalg.solve(Ja @ Ja.T + damping * damping * np.eye(len(Ja)), b)).tolist()
        return np.linalg.lstsq(Ja, np.asarray(b, dtype=float), rcond=None)[0].tolist()
    if damping > 0.0:
        Ja = np.asarray(J, dtype=float)  # an array keeps its memory order: BLAS's rounding does too
        return (Ja.T @ solve3((Ja @ Ja.T + damping * damping * np.eye(3)).tolist(), _floats(b))).tolist()
    if len(J[0]) == 3:
        return solve3(J if type(J) is list else J.tolist(), _floats(b))
    Ja = np.asarray(J, dtype=float)
    return (Ja.T @ np.linalg.solve(Ja @ Ja.T, b)).tolist()


def _floats(values) -> list:
    """A 3-vector (list or array) as a list of plain floats."""
    return values if type(values) is list else np.asarray(values, dtype=float).tolist()


def smc_torque(K, J, s_x, damping: float = 0.0) -> list:
    """τ = −K J⁺ s_x (paper eq. 18) as a list of plain floats: K a sequence of nv gains (N·m·s/rad),
    J (n × nv) and s_x (n; n = 3, or 6 with orientation) as ``pinv_apply`` takes them."""
    return [-k * a for k, a in zip(K, pinv_apply(J, s_x, damping))]


def null_space_torque(J: np.ndarray, q: np.ndarray, v: np.ndarray, q_start: np.ndarray,
                      damping: float, rate: float) -> np.ndarray:
    """τ_ns = −D (I − J⁺J)(q̇ + r (q − q_start)): joint damping toward the start posture,
    projected so that it does not move the gripper point (zero for a square, full-rank J)."""
    w = v + rate * (q - q_start)
    return -damping * (w - J.T @ np.linalg.solve(J @ J.T, J @ w))


def null_space_terms(gains, plant, posture=None):
    """(D, r, q_start) of ``null_space_torque`` for ``gains`` (a ``ControllerGains``), or None
    when it is off: ``gains.null_space_damping`` = 0, or no redundancy (nv ≤ the task's
    dimension).  q_start is
    ``posture``, by default the plant's default positions (needs nq = nv)."""
    if not (gains.null_space_damping > 0.0 and plant.num_velocities() > TASK_DIM[gains.task]):
        return None
    start = plant.GetPositions(plant.CreateDefaultContext()) if posture is None else posture
    return (gains.null_space_damping, gains.null_space_rate, np.asarray(start, float))


class SlidingModeController(LeafSystem):
    """Inputs ``s_x`` (n) and ``J`` (n·nv, row-major; n = 3, or 6 for a task with orientation);
    output ``tau`` (nv joint torques).

    ``K`` is a scalar or a length-nv diagonal (N·m·s/rad).  The output is in
    generalized-velocity order; ``actuation_matrix`` (the plant's B, nv × nu)
    maps it to the plant's actuation input order: u = Bᵀ τ.
    """

    def __init__(self, nv: int, K=50.0, actuation_matrix=None, pinv_damping: float = 0.0,
                 null_space=None, dim: int = 3):
        """``null_space`` = (D, r, q_start) adds ``null_space_torque`` and an input ``state``
        ([q; v], nq = nv) to read q and q̇."""
        super().__init__()
        self._null_space = null_space
        self._nv = nv
        self._dim = dim
        self._damping = float(pinv_damping)
        self._K = np.broadcast_to(np.asarray(K, dtype=float), (nv,)).copy()
        self._K_floats = tuple(self._K.tolist())
        self._BT = None if actuation_matrix is None else np.asarray(actuation_matrix).T
        nu = nv if actuation_matrix is None else self._BT.shape[0]
        self._s_x_in = self.DeclareVectorInputPort("s_x", dim)
        self._J_in = self.DeclareVectorInputPort("J", dim * nv)
        self._state_in = self.DeclareVectorInputPort("state", 2 * nv) if null_space else None
        deps = {self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, "tau", nv, self._tau, deps)
        self.DeclareVectorOutputPort(
            "tau", nv, lambda c, o: o.SetFromVector(self._eval(c)), prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(
            "u", nu, lambda c, o: o.SetFromVector(
                self._eval(c) if self._BT is None else self._BT @ self._eval(c)),
            prerequisites_of_calc=deps)

    def torque(self, s_x: np.ndarray, J: np.ndarray) -> np.ndarray:
        """τ = −K J⁺ s_x (``smc_torque``) for an n × nv Jacobian J."""
        return np.array(smc_torque(self._K_floats, J, s_x, self._damping))

    def _tau(self, context) -> np.ndarray:
        J = self._J_in.Eval(context).reshape(self._dim, self._nv)
        tau = self.torque(self._s_x_in.Eval(context), J)
        if self._null_space:
            qv = self._state_in.Eval(context)
            D, rate, q_start = self._null_space
            tau = tau + null_space_torque(J, qv[:self._nv], qv[self._nv:], q_start, D, rate)
        return tau
