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


def _solve3_floats(J, b):
    """J⁻¹ b for a 3 × 3 J (3 rows of plain floats) by Cramer's rule; None when J is
    numerically singular."""
    (a, b_, c), (d, e, f), (g, h, i) = J
    co0, co1, co2 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * co0 + b_ * co1 + c * co2
    scale = max(abs(a), abs(b_), abs(c), abs(d), abs(e), abs(f), abs(g), abs(h), abs(i)) or 1.0
    if abs(det) <= 1e-12 * scale**3:
        return None
    x, y, z = b
    return [(co0 * x + (c * h - b_ * i) * y + (b_ * f - c * e) * z) / det,
            (co1 * x + (a * i - c * g) * y + (c * d - a * f) * z) / det,
            (co2 * x + (b_ * g - a * h) * y + (a * e - b_ * d) * z) / det]


def solve3(J: np.ndarray, b: np.ndarray) -> np.ndarray:
    """J⁻¹ b for a 3 × 3 J by Cramer's rule in plain floats (numpy's solve costs ~15 µs here).

    Falls back to a least-squares solve when J is numerically singular.
    """
    out = _solve3_floats(np.asarray(J, dtype=float).tolist(), np.asarray(b, dtype=float).tolist())
    if out is None:
        return np.linalg.lstsq(J, b, rcond=None)[0]
    return np.array(out)


def smc_torque_values(K, J, s_x, damping: float = 0.0) -> list:
    """``smc_torque`` in plain floats: K a sequence of nv gains, J a list of 3 rows, s_x a
    list of 3; returns τ as a list (the per-derivative fast path)."""
    if damping > 0.0 or len(J[0]) != 3:
        return smc_torque(np.asarray(K, dtype=float), np.array(J), np.array(s_x), damping).tolist()
    qdot_s = _solve3_floats(J, s_x)
    if qdot_s is None:
        qdot_s = np.linalg.lstsq(np.array(J), np.array(s_x), rcond=None)[0].tolist()
    return [-k * a for k, a in zip(K, qdot_s)]


def smc_torque(K: np.ndarray, J: np.ndarray, s_x: np.ndarray, damping: float = 0.0) -> np.ndarray:
    """τ = −K J⁺ s_x: a linear solve for square J, the minimum-norm solution otherwise.

    With ``damping`` λ > 0 (m/rad), J⁺ is the damped pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹, which
    stays bounded through singular configurations at the cost of a small bias near them.
    """
    if damping > 0.0:
        qdot_s = J.T @ solve3(J @ J.T + damping * damping * np.eye(3), s_x)
    elif J.shape[1] == 3:
        return np.array(smc_torque_values(np.broadcast_to(K, (3,)).tolist(), J.tolist(),
                                          np.asarray(s_x, dtype=float).tolist()))
    else:
        qdot_s = J.T @ np.linalg.solve(J @ J.T, s_x)
    return -K * qdot_s


def null_space_torque(J: np.ndarray, q: np.ndarray, v: np.ndarray, q_start: np.ndarray,
                      damping: float, rate: float) -> np.ndarray:
    """τ_ns = −D (I − J⁺J)(q̇ + r (q − q_start)): joint damping toward the start posture,
    projected so that it does not move the gripper point (zero for a square, full-rank J)."""
    w = v + rate * (q - q_start)
    return -damping * (w - J.T @ np.linalg.solve(J @ J.T, J @ w))


class SlidingModeController(LeafSystem):
    """Inputs ``s_x`` (3) and ``J`` (3·nv, row-major); output ``tau`` (nv joint torques).

    ``K`` is a scalar or a length-nv diagonal (N·m·s/rad).  The output is in
    generalized-velocity order; ``actuation_matrix`` (the plant's B, nv × nu)
    maps it to the plant's actuation input order: u = Bᵀ τ.
    """

    def __init__(self, nv: int, K=50.0, actuation_matrix=None, pinv_damping: float = 0.0,
                 null_space=None):
        """``null_space`` = (D, r, q_start) adds ``null_space_torque`` and an input ``state``
        ([q; v], nq = nv) to read q and q̇."""
        super().__init__()
        self._null_space = null_space
        self._nv = nv
        self._damping = float(pinv_damping)
        self._K = np.broadcast_to(np.asarray(K, dtype=float), (nv,)).copy()
        self._BT = None if actuation_matrix is None else np.asarray(actuation_matrix).T
        nu = nv if actuation_matrix is None else self._BT.shape[0]
        self._s_x_in = self.DeclareVectorInputPort("s_x", 3)
        self._J_in = self.DeclareVectorInputPort("J", 3 * nv)
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
        """τ = −K J⁺ s_x for a 3 × nv Jacobian J."""
        return smc_torque(self._K, J, s_x, self._damping)

    def _tau(self, context) -> np.ndarray:
        J = self._J_in.Eval(context).reshape(3, self._nv)
        tau = self.torque(self._s_x_in.Eval(context), J)
        if self._null_space:
            qv = self._state_in.Eval(context)
            D, rate, q_start = self._null_space
            tau = tau + null_space_torque(J, qv[:self._nv], qv[self._nv:], q_start, D, rate)
        return tau
