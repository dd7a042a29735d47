"""Second-order sliding-mode controller τ = −K J⁺(q) s_x  (SPEC section 2.3, paper eq. 18).

Model-free: the only robot knowledge it takes is the Jacobian J (kinematics).
For a square J the pseudoinverse product J⁺ s_x is a linear solve; for a
redundant arm (more joints than 3) it is the minimum-norm solution
Jᵀ (J Jᵀ)⁻¹ s_x.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.error import TASK_DIM
from ptint_drake.systems.task.views import borrow


@njit(cache=True, inline="always")
def _solve3(A, b, out, general=None) -> bool:
    """``out`` ← A⁻¹ b for a 3 × 3 A by Cramer's rule; the least-squares solution when A is
    numerically singular (``general`` given, else False and ``out`` not written: see
    ``pinv_solve_into``)."""
    a, b_, c = A[0, 0], A[0, 1], A[0, 2]
    d, e, f = A[1, 0], A[1, 1], A[1, 2]
    g, h, i = A[2, 0], A[2, 1], A[2, 2]
    co0, co1, co2 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * co0 + b_ * co1 + c * co2
    scale = 0.0  # max |A_ij| (NaN in A makes det NaN: the solve below)
    for r in range(3):
        for c_ in range(3):
            scale = max(scale, abs(A[r, c_]))
    if scale == 0.0:
        scale = 1.0
    if abs(det) <= 1e-12 * scale**3:
        if general is None:
            return False
        out[:] = np.linalg.lstsq(A, b.copy())[0]
        return True
    x, y, z = b[0], b[1], b[2]
    out[0] = (co0 * x + (c * h - b_ * i) * y + (b_ * f - c * e) * z) / det
    out[1] = (co1 * x + (a * i - c * g) * y + (c * d - a * f) * z) / det
    out[2] = (co2 * x + (b_ * g - a * h) * y + (a * e - b_ * d) * z) / det
    return True


@njit(cache=True)
def pinv_work_size(n: int, nv: int) -> int:
    """Floats of ``pinv_solve_into``'s scratch for an n × nv Jacobian."""
    return max(n * n + n, n * nv + max(n, nv) + 2 * min(n, nv))


@njit(cache=True, inline="always")
def _householder(A, rdiag, betas) -> bool:
    """Householder QR of the m × p (m ≥ p) ``A`` in place: column k below the diagonal and on it
    holds the k-th reflector v (H_k = I − β_k v vᵀ, β_k = 1 / (s (s + |a_kk|)) in ``betas``),
    above the diagonal R, and ``rdiag`` R's diagonal.  False when a column has nothing left to reflect or
    min |r_ii| ≤ 1e-10 max |r_ii| (numerically rank-deficient: the caller falls back to the SVD)."""
    m, p = A.shape
    for k in range(p):
        s = 0.0
        for i in range(k, m):
            s += A[i, k] * A[i, k]
        s = np.sqrt(s)
        if s == 0.0 or s != s:
            return False
        a = A[k, k]
        alpha = -s if a > 0.0 else s
        A[k, k] = a - alpha
        beta = 1.0 / (s * (s + abs(a)))
        betas[k] = beta
        for j in range(k + 1, p):
            f = 0.0
            for i in range(k, m):
                f += A[i, k] * A[i, j]
            f *= beta
            for i in range(k, m):
                A[i, j] -= f * A[i, k]
        rdiag[k] = alpha
    big, small = 0.0, np.inf
    for k in range(p):
        big, small = max(big, abs(rdiag[k])), min(small, abs(rdiag[k]))
    return small > 1e-10 * big


@njit(cache=True, inline="always")
def _reflect(A, betas, k, y) -> None:
    """y[k:] ← H_k y[k:] (``_householder``'s k-th reflector)."""
    m = A.shape[0]
    f = 0.0
    for i in range(k, m):
        f += A[i, k] * y[i]
    f *= betas[k]
    for i in range(k, m):
        y[i] -= f * A[i, k]


@njit(cache=True, inline="always")
def _householder_solve(J, b, out, work) -> bool:
    """``out`` ← the least-squares solution of J x = b (n ≥ nv: J = QR, x = R⁻¹ Qᵀ b) or its
    minimum-norm solution (n < nv: Jᵀ = QR, x = Q R⁻ᵀ b), by Householder QR in ``work``
    (``pinv_work_size``) — for a full-rank J what numpy's ``lstsq`` (an SVD)
    returns, to rounding, for a fraction of its cost and no new memory.  False (``out`` not
    written) for a numerically rank-deficient J (``_householder``)."""
    n, nv = J.shape
    m, p = max(n, nv), min(n, nv)
    A = work[:m * p].reshape(m, p)
    y = work[m * p:m * p + m]
    rdiag, betas = work[m * p + m:m * p + m + p], work[m * p + m + p:m * p + m + 2 * p]
    tall = n >= nv
    for i in range(m):
        for j in range(p):
            A[i, j] = J[i, j] if tall else J[j, i]
    if not _householder(A, rdiag, betas):
        return False
    if tall:
        for i in range(n):
            y[i] = b[i]
        for k in range(p):
            _reflect(A, betas, k, y)
        for i in range(p - 1, -1, -1):
            acc = y[i]
            for j in range(i + 1, p):
                acc -= A[i, j] * out[j]
            out[i] = acc / rdiag[i]
    else:
        for i in range(p):  # Rᵀ z = b
            acc = b[i]
            for j in range(i):
                acc -= A[j, i] * y[j]
            y[i] = acc / rdiag[i]
        for i in range(p, m):
            y[i] = 0.0
        for k in range(p - 1, -1, -1):
            _reflect(A, betas, k, y)
        for i in range(m):
            out[i] = y[i]
    return True


@njit(cache=True)
def pinv_solve(J, b, damping: float):
    """J⁺ b for an n × nv Jacobian J and an n-vector b (the pseudo-inverse of eq. 18).

    3 rows: a 3 × 3 solve (Cramer's rule, ``_solve3``) for a square J, the minimum-norm solution
    Jᵀ(JJᵀ)⁻¹ b for more joints.  6 rows (position and orientation, ``systems.task.error``): the
    minimum-norm least-squares solution (``lstsq``): J⁻¹ b for a square J, the least-squares fit
    for fewer joints than rows (a 5-joint wrist), the minimum-norm one for more.  With
    ``damping`` λ > 0 (m/rad), J⁺ is the damped pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹, which stays
    bounded through singular configurations at the cost of a small bias near them.
    (``pinv_solve_into`` in a new array.)"""
    n, nv = J.shape
    out = np.empty(nv)
    pinv_solve_into(J, b, damping, out, np.empty(pinv_work_size(n, nv)), True)
    return out


@njit(cache=True)
def pinv_solve_into(J, b, damping: float, out, work, general=None) -> bool:
    """``out`` (nv) ← ``pinv_solve(J, b, damping)``; ``work``: a scratch vector of
    ``pinv_work_size(n, nv)`` (J Jᵀ and its solve then take no new memory for up to 8 joints,
    nor does a square 3 × 3 J, nor the 6-row undamped solve of a full-rank J:
    ``_householder_solve``; a rank-deficient one goes to numpy's ``lstsq``).  3 rows:
    ``pinv3_solve_into``; more: ``_pinv_rows_solve_into``.

    Without ``general`` (None) the kernel leaves out numpy's ``lstsq``, ``solve`` and products
    (half of a cold compile, for cases a run rarely meets): it returns False, ``out`` not
    written, where it would need them (a numerically singular J, more than 8 joints, a damped
    6-row solve); called again with ``general=True`` it gives the very same bits as it always
    did.  True when ``out`` holds the solution."""
    if J.shape[0] == 3:
        return pinv3_solve_into(J, b, damping, out, work, general)
    return _pinv_rows_solve_into(J, b, damping, out, work, general)


@njit(cache=True, inline="always")
def pinv3_solve_into(J, b, damping: float, out, work, general=None) -> bool:
    """``pinv_solve_into`` for 3 rows (the position task, whose fused kernel calls this one, so
    that its compilation leaves out the 6-row solves): Cramer's rule for a square undamped J,
    else Jᵀ (J Jᵀ + λ²I)⁻¹ b with the 3 × 3 solve by Cramer's rule too."""
    nv = J.shape[1]
    if damping <= 0.0 and nv == 3:
        return _solve3(J, b, out, general)
    if nv > 8:
        if general is None:
            return False
        return _dense_pinv_into(J, b, damping, out, work)
    A = borrow(work, 0, (3, 3))
    _gram(J, A)
    for i in range(3):
        A[i, i] += damping * damping
    y = work[9:12]
    if not _solve3(A, b, y, general):
        return False
    _transpose_times(J, y, out)
    return True


@njit(cache=True)
def _pinv_rows_solve_into(J, b, damping: float, out, work, general=None) -> bool:
    """``pinv_solve_into`` for 6 rows: undamped, the Householder QR (``_householder_solve``) or
    for a rank-deficient J numpy's ``lstsq``; damped, ``_dense_pinv_into``."""
    n, nv = J.shape
    if damping <= 0.0:
        if pinv_work_size(n, nv) <= len(work) and _householder_solve(J, b, out, work):
            return True
        if general is None:
            return False
        out[:] = np.linalg.lstsq(np.ascontiguousarray(J), b.copy())[0]
        return True
    if general is None:
        return False
    return _dense_pinv_into(J, b, damping, out, work)


@njit(cache=True)
def _dense_pinv_into(J, b, damping: float, out, work) -> bool:
    """``pinv_solve_into``'s damped (or minimum-norm) solve of more than 8 joints or 6 rows:
    Jᵀ (J Jᵀ + λ²I)⁻¹ b with numpy's products and ``solve``."""
    n, nv = J.shape
    if nv > 8:
        A = J @ J.T
    else:
        A = work[:n * n].reshape(n, n)
        _gram(J, A)
    for i in range(n):
        A[i, i] += damping * damping
    y = work[n * n:n * n + n]
    if n == 3:
        _solve3(A, b, y, True)
    else:
        y[:] = np.linalg.solve(A, b.copy())
    if nv > 8:
        out[:] = J.T @ y
    else:
        _transpose_times(J, y, out)
    return True


@njit(cache=True, inline="always")
def _gram(J, A) -> None:
    """A ← J Jᵀ by loops (BLAS costs more than it saves on a few rows)."""
    n, nv = J.shape
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(nv):
                acc += J[i, k] * J[j, k]
            A[i, j] = acc


@njit(cache=True, inline="always")
def _transpose_times(J, y, x) -> None:
    """x ← Jᵀ y by loops."""
    n, nv = J.shape
    for k in range(nv):
        x[k] = 0.0
        for i in range(n):
            x[k] += J[i, k] * y[i]


@njit(cache=True)
def sliding_mode_torque(K, J, s_x, damping: float):
    """τ = −K J⁺ s_x (paper eq. 18): K the nv gains (N·m·s/rad), J (n × nv) and s_x (n; n = 3,
    or 6 with orientation) as ``pinv_solve`` takes them (``sliding_mode_torque_into`` in a new
    array)."""
    n, nv = J.shape
    tau = np.empty(nv)
    sliding_mode_torque_into(K, J, s_x, damping, tau, np.empty(pinv_work_size(n, nv)), True)
    return tau


@njit(cache=True)
def sliding_mode_torque_into(K, J, s_x, damping: float, tau, work, general=None) -> bool:
    """``tau`` (nv) ← τ = −K J⁺ s_x (eq. 18) without new memory for up to 8 joints
    (``pinv_solve_into``, then ``gain_torque``; ``work`` ≥ n² + n); False (``tau`` not written)
    where the solve needs ``general`` (``pinv_solve_into``)."""
    if not pinv_solve_into(J, s_x, damping, tau, work, general):
        return False
    gain_torque(K, tau)
    return True


@njit(cache=True, inline="always")
def gain_torque(K, tau) -> None:
    """``tau`` ← −K ⊙ ``tau``: eq. 18's gain on J⁺ s_x."""
    for k in range(len(tau)):
        tau[k] = -K[k] * tau[k]


def pinv_apply(J, b, damping: float = 0.0) -> np.ndarray:
    """``pinv_solve`` on any array-like J (n × nv) and b (n)."""
    return pinv_solve(np.ascontiguousarray(J, dtype=float), np.ascontiguousarray(b, dtype=float),
                      float(damping))


def smc_torque(K, J, s_x, damping: float = 0.0) -> np.ndarray:
    """``sliding_mode_torque`` on any array-likes: K (nv, or a scalar), J (n × nv), s_x (n)."""
    Ja = np.ascontiguousarray(J, dtype=float)
    K = np.broadcast_to(np.asarray(K, dtype=float), (Ja.shape[1],)).copy()
    return sliding_mode_torque(K, Ja, np.ascontiguousarray(s_x, dtype=float), float(damping))


# The joint-limit term of the null-space posture task: per radian inside the margin band, this
# many times the pull toward the rest posture (issue 45).
LIMIT_WEIGHT = 10.0


def limit_push(q: np.ndarray, lower: np.ndarray, upper: np.ndarray, margin: float) -> np.ndarray:
    """How deep each joint is inside the band of width ``margin`` (rad) before its limits:
    positive near the upper limit, negative near the lower one, 0 in between (and for a joint
    without limits)."""
    q = np.asarray(q, dtype=float)
    return np.maximum(q - (upper - margin), 0.0) - np.maximum((lower + margin) - q, 0.0)


def null_space_torque(J: np.ndarray, q: np.ndarray, v: np.ndarray, q_start: np.ndarray,
                      damping: float, rate: float, limits=None) -> np.ndarray:
    """τ_ns = −D (I − J⁺J)(q̇ + r (q − q_start) + r w_L limit_push(q)): joint damping toward the
    start (rest) posture and away from the joint limits (``limits`` = (lower, upper, margin), or
    None; w_L = ``LIMIT_WEIGHT``), projected so that it does not move the gripper point (zero for
    a square, full-rank J).  At a singular J (e.g. a 7-joint arm stretched straight up, q = 0) the
    projection takes J J^T's pseudo-inverse instead of failing."""
    w = v + rate * (q - q_start)
    if limits is not None:
        w = w + rate * LIMIT_WEIGHT * limit_push(q, *limits)
    try:
        return -damping * (w - J.T @ np.linalg.solve(J @ J.T, J @ w))
    except np.linalg.LinAlgError:
        return -damping * (w - J.T @ (np.linalg.pinv(J @ J.T) @ (J @ w)))


def null_space_terms(gains, plant, posture=None):
    """(D, r, q_rest, limits) of ``null_space_torque`` for ``gains`` (a ``ControllerGains``), or
    None when it is off: ``gains.null_space_damping`` = 0, or no redundancy (nv ≤ the task's
    dimension).  q_rest is ``gains.null_space_posture_deg`` when given, else ``posture``, by
    default the plant's default positions (needs nq = nv); ``limits`` = (lower, upper, margin)
    from the plant's position limits and ``gains.null_space_limit_margin_deg``, or None (0)."""
    if not (gains.null_space_damping > 0.0 and plant.num_velocities() > TASK_DIM[gains.task]):
        return None
    rest = list(getattr(gains, "null_space_posture_deg", None) or [])
    if rest:
        start = np.radians(np.asarray(rest, dtype=float))
    else:
        start = plant.GetPositions(plant.CreateDefaultContext()) if posture is None else posture
    margin = float(getattr(gains, "null_space_limit_margin_deg", 0.0))
    limits = None if margin <= 0.0 else (plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits(),
                                         np.radians(margin))
    return (gains.null_space_damping, gains.null_space_rate, np.asarray(start, float), limits)


class SlidingModeController(LeafSystem):
    """Inputs ``s_x`` (n) and ``J`` (n·nv, row-major; n = 3, or 6 for a task with orientation);
    output ``tau`` (nv joint torques).

    ``K`` is a scalar or a length-nv diagonal (N·m·s/rad).  The output is in
    generalized-velocity order; ``actuation_matrix`` (the plant's B, nv × nu)
    maps it to the plant's actuation input order: u = Bᵀ τ.
    """

    def __init__(self, nv: int, K=50.0, actuation_matrix=None, pinv_damping: float = 0.0,
                 null_space=None, dim: int = 3):
        """``null_space`` = (D, r, q_start, limits) adds ``null_space_torque`` and an input ``state``
        ([q; v], nq = nv) to read q and q̇."""
        super().__init__()
        self._null_space = null_space
        self._nv = nv
        self._dim = dim
        self._damping = float(pinv_damping)
        self._K = np.broadcast_to(np.asarray(K, dtype=float), (nv,)).copy()
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
        """τ = −K J⁺ s_x (``sliding_mode_torque``) for an n × nv Jacobian J."""
        return sliding_mode_torque(self._K, np.ascontiguousarray(J), np.asarray(s_x, dtype=float),
                                   self._damping)

    def _tau(self, context) -> np.ndarray:
        J = self._J_in.Eval(context).reshape(self._dim, self._nv)
        tau = self.torque(self._s_x_in.Eval(context), J)
        if self._null_space:
            qv = self._state_in.Eval(context)
            D, rate, q_start, limits = self._null_space
            tau = tau + null_space_torque(J, qv[:self._nv], qv[self._nv:], q_start, D, rate, limits)
        return tau
