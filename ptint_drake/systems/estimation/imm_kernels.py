"""The compiled kernels of the IMM filter of ``imm`` (``estimator: auto``; its module docstring
has the models and the cycle's equations): one ``@njit(cache=True)`` function per equation, a
model selected by its code (its index in ``MODELS``), the filter's constants beside them.
Arrays: X = χⱼ (m×10), Ps = Pⱼ (m×10×10), μ (m), m = len(MODELS) = 4.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

MODELS = ("cv", "ca", "turn", "fall")  # a model's code in the kernels is its index here
CV, CA, TURN, FALL = range(len(MODELS))
N = 10  # state size: p, v, a (3 each) and Ω
R_MIN = 1.0e-12  # m², floor of the measurement variance
Q_CV = 1.0e-6  # m²/s³, white acceleration of ``cv``
Q_FALL = 1.0e-4  # m²/s³, white acceleration of ``fall`` (about g, e.g. drag)
GRAVITY = np.array([0.0, 0.0, -9.81])  # m/s², the world's (z up), known to the camera system
Q_CA = 1.0e-2  # m²/s⁵, white jerk of ``ca``
Q_TURN = 1.0e-4  # m²/s⁵, white jerk of ``turn``
Q_OMEGA = 0.1  # rad⁴/s⁵, random walk of Ω in ``turn``
A_CV = 0.3  # m/s², standard deviation of the (unused) acceleration of ``cv``
V0, A0 = 1.0, 10.0  # m/s, m/s²: initial standard deviations
OMEGA0, OMEGA_SD0, OMEGA_MAX = 1.0, 3.0, 100.0  # rad²/s²: initial Ω, its sd, largest Ω
SOJOURN = 20.0  # s, mean time the motion stays with one model
MU0 = np.full(len(MODELS), 1.0 / len(MODELS))
NO_SAMPLE = np.empty(0)  # the ``z`` of a cycle without a new sample (predict only)


@njit(cache=True)
def _turn_terms(omega2: float, dt: float) -> tuple:
    """(s, c, r) = (sin(ωΔ)/ω, cos(ωΔ), (1 − cos ωΔ)/Ω) for Ω = ω² ≥ 0 (series for small ωΔ)."""
    x = omega2 * dt * dt
    if x < 1.0e-4:
        s = dt * (1.0 - x / 6.0 + x * x / 120.0)
        c = 1.0 - x / 2.0 + x * x / 24.0
        r = dt * dt * (0.5 - x / 24.0 + x * x / 720.0)
        return s, c, r
    w = math.sqrt(omega2)
    return math.sin(w * dt) / w, math.cos(w * dt), (1.0 - math.cos(w * dt)) / omega2


@njit(cache=True)
def _product(A: np.ndarray, B: np.ndarray, transpose_b: bool) -> np.ndarray:
    """A B (or A Bᵀ) of two small matrices, as plain loops (compiles and runs faster than BLAS
    at 10×10)."""
    n, m = A.shape[0], B.shape[0] if transpose_b else B.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for j in range(m):
            acc = 0.0
            for k in range(A.shape[1]):
                acc += A[i, k] * (B[j, k] if transpose_b else B[k, j])
            out[i, j] = acc
    return out


@njit(cache=True)
def _apply(A: np.ndarray, x: np.ndarray) -> np.ndarray:
    """A x of a small matrix and a vector."""
    out = np.zeros(A.shape[0])
    for i in range(A.shape[0]):
        for k in range(A.shape[1]):
            out[i] += A[i, k] * x[k]
    return out


@njit(cache=True)
def per_axis(values: tuple, k: int) -> np.ndarray:
    """The same k×k block (``values`` row by row) for each of the three axes: (3k)×(3k),
    ordered [p_xyz, v_xyz, …]."""
    out = np.zeros((3 * k, 3 * k))
    for axis in range(3):
        for i in range(k):
            for j in range(k):
                out[3 * i + axis, 3 * j + axis] = values[k * i + j]
    return out


@njit(cache=True)
def _axis_block(s: float, c: float, r: float, omega2: float) -> np.ndarray:
    """The 9×9 transition of [p, v, a] (three axes) for given turn terms:
    p ← p + s v + r a, v ← c v + s a, a ← −Ω s v + c a."""
    return per_axis((1.0, s, r, 0.0, c, s, 0.0, -omega2 * s, c), 3)


@njit(cache=True)
def jerk_covariance(dt: float, q: float) -> np.ndarray:
    """9×9 Q(Δ) of white jerk with density q on [p, v, a] of each axis."""
    d2, d3 = dt * dt, dt * dt * dt
    return per_axis((q * (d3 * d2 / 20.0), q * (d2 * d2 / 8.0), q * (d3 / 6.0),
                     q * (d2 * d2 / 8.0), q * (d3 / 3.0), q * (d2 / 2.0),
                     q * (d3 / 6.0), q * (d2 / 2.0), q * dt), 3)


@njit(cache=True)
def _transition(model: int, x: np.ndarray, dt: float) -> tuple:
    """(F, Q, χ⁻) of one model (its code, ``MODELS``) over dt: the (linearised) transition F
    (10×10), the process noise Q(Δ) and the predicted state (the module docstring's models)."""
    F, Q = np.eye(N), np.zeros((N, N))
    if model == CV or model == FALL:
        F[0:9, 0:9] = _axis_block(dt, 1.0, 0.0, 0.0)
        F[:, 6:9] = 0.0  # a is not estimated: 0 (cv) or g (fall)
        d2 = dt * dt
        q = Q_CV if model == CV else Q_FALL
        Q[0:6, 0:6] = per_axis((q * (d2 * dt / 3.0), q * (d2 / 2.0), q * (d2 / 2.0), q * dt), 2)
        for i in range(6, 9):
            Q[i, i] = A_CV * A_CV
        x_new = _apply(F, x)
        if model == FALL:
            x_new[0:3] += 0.5 * d2 * GRAVITY
            x_new[3:6] += dt * GRAVITY
            x_new[6:9] += GRAVITY
    elif model == CA:
        F[0:9, 0:9] = _axis_block(dt, 1.0, 0.5 * dt * dt, 0.0)
        Q[0:9, 0:9] = jerk_covariance(dt, Q_CA)
        x_new = _apply(F, x)
    else:
        omega2 = min(max(x[9], 0.0), OMEGA_MAX)
        s, c, r = _turn_terms(omega2, dt)
        F9 = _axis_block(s, c, r, omega2)
        h = 1.0e-5 * max(1.0, omega2)
        s_h, c_h, r_h = _turn_terms(omega2 + h, dt)
        F[0:9, 0:9] = F9
        F[0:9, 9] = _apply(_axis_block(s_h, c_h, r_h, omega2 + h) - F9, x[0:9]) / h  # ∂(F χ)/∂Ω
        Q[0:9, 0:9] = jerk_covariance(dt, Q_TURN)
        Q[9, 9] = Q_OMEGA * dt
        x_new = np.zeros(N)
        x_new[0:9] = _apply(F9, x[0:9])
        x_new[9] = omega2
    return F, Q, x_new


@njit(cache=True)
def predict_model(model: int, x: np.ndarray, P: np.ndarray, dt: float) -> tuple:
    """(χ⁻, P⁻ = F P Fᵀ + Q) of one model (its code, ``MODELS``) predicted over dt."""
    F, Q, x_new = _transition(model, x, dt)
    P_new = _product(_product(F, P, False), F, True) + Q
    return x_new, 0.5 * (P_new + P_new.T)


@njit(cache=True)
def _inverse3(S: np.ndarray) -> tuple:
    """(S⁻¹, det S) of a 3×3 matrix (the adjugate over the determinant)."""
    inv = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            a, b = (j + 1) % 3, (j + 2) % 3
            c, d = (i + 1) % 3, (i + 2) % 3
            inv[i, j] = S[a, c] * S[b, d] - S[a, d] * S[b, c]
    det = S[0, 0] * inv[0, 0] + S[0, 1] * inv[1, 0] + S[0, 2] * inv[2, 0]
    return inv / det, det


@njit(cache=True)
def correct(x: np.ndarray, P: np.ndarray, z: np.ndarray, R: float) -> tuple:
    """(χ, P, log-likelihood) after the position measurement z (Joseph form):
    S = H P Hᵀ + R I₃, K = P Hᵀ S⁻¹, y = z − p, χ ← χ + K y,
    P ← (I − K H) P (I − K H)ᵀ + R K Kᵀ, log N(y; 0, S) (S is positive definite)."""
    S = P[0:3, 0:3] + R * np.eye(3)
    y = z - x[0:3]
    S_inv, det = _inverse3(S)
    K = _product(P[:, 0:3], S_inv, False)
    x = x + _apply(K, y)
    x[9] = min(max(x[9], 0.0), OMEGA_MAX)
    A = np.eye(N)
    A[:, 0:3] -= K
    P = _product(_product(A, P, False), A, True) + R * _product(K, K, True)
    Sy = _apply(S_inv, y)
    loglik = -0.5 * (y[0] * Sy[0] + y[1] * Sy[1] + y[2] * Sy[2] + math.log(det)
                     + 3.0 * math.log(2.0 * math.pi))
    return x, 0.5 * (P + P.T), loglik


@njit(cache=True)
def transition_matrix(dt: float) -> np.ndarray:
    """Π(Δ): Πᵢⱼ = P(model j now | model i before); stay with probability exp(−Δ/SOJOURN)."""
    stay = math.exp(-max(dt, 0.0) / SOJOURN)
    m = len(MODELS)
    return np.full((m, m), (1.0 - stay) / (m - 1)) + (stay - (1.0 - stay) / (m - 1)) * np.eye(m)


@njit(cache=True)
def mix(X: np.ndarray, Ps: np.ndarray, mu: np.ndarray, dt: float) -> tuple:
    """(χ⁰ⱼ, P⁰ⱼ, c_j) of the IMM's mixing step: c_j = Σᵢ Πᵢⱼ μᵢ, μᵢ|ⱼ = Πᵢⱼ μᵢ / c_j,
    χ⁰ⱼ = Σᵢ μᵢ|ⱼ χᵢ, P⁰ⱼ = Σᵢ μᵢ|ⱼ (Pᵢ + (χᵢ − χ⁰ⱼ)(χᵢ − χ⁰ⱼ)ᵀ)."""
    m, n = X.shape
    Pi = transition_matrix(dt)
    c = _apply(Pi.T, mu)
    W = np.empty((m, m))  # W[i, j] = μ_{i|j}
    for i in range(m):
        for j in range(m):
            W[i, j] = Pi[i, j] * mu[i] / c[j]
    X0 = _product(W.T, X, False)
    P0 = np.empty_like(Ps)
    D = np.empty((m, n))
    for j in range(m):
        for i in range(m):
            D[i] = (X[i] - X0[j]) * W[i, j]
        for r in range(n):
            for s in range(n):
                spread, mean = 0.0, 0.0
                for i in range(m):
                    mean += W[i, j] * Ps[i, r, s]
                    spread += D[i, r] * (X[i, s] - X0[j, s])
                P0[j, r, s] = mean + spread
    return X0, P0, c


@njit(cache=True)
def imm_cycle(X: np.ndarray, Ps: np.ndarray, mu: np.ndarray, dt: float, z: np.ndarray,
              R: float) -> tuple:
    """One IMM cycle over dt, correcting with the position z (3): (X, Ps, μ) after it, μⱼ ∝
    c_j N(y; 0, S) (in logs).  Without a sample (z = ``NO_SAMPLE``, empty) ``coast``."""
    if len(z) == 0:
        return coast(X, Ps, mu, dt)
    X0, P0, c = mix(X, Ps, mu, dt)
    logs = np.zeros(len(MODELS))
    for j in range(len(MODELS)):
        X0[j], P0[j] = predict_model(j, X0[j], P0[j], dt)
        X0[j], P0[j], logs[j] = correct(X0[j], P0[j], z, R)
    logw = np.log(np.maximum(c, 1e-300)) + logs
    w = np.exp(logw - logw.max())
    return X0, P0, w / w.sum()


@njit(cache=True)
def coast(X: np.ndarray, Ps: np.ndarray, mu: np.ndarray, dt: float) -> tuple:
    """A cycle without a sample: each model predicts its own (χⱼ, Pⱼ) over dt, unmixed, and μ
    is held — the filter's prediction conditioned on no switch since the last sample (``imm``'s
    docstring, "Through a gap", has why: Πᵀμ would leak the other models in)."""
    X1, P1 = np.empty_like(X), np.empty_like(Ps)
    for j in range(len(MODELS)):
        X1[j], P1[j] = predict_model(j, X[j], Ps[j], dt)
    return X1, P1, mu.copy()


@njit(cache=True)
def initial_state(z: np.ndarray, R: float) -> tuple:
    """(X, Ps, μ) at the first sample: χ = [z, 0, 0, OMEGA0] for every model, P diagonal with
    [R (3), V0² (3), A0² (3), OMEGA_SD0²], μ = ``MU0``."""
    m = len(MODELS)
    X, Ps = np.zeros((m, N)), np.zeros((m, N, N))
    for j in range(m):
        X[j, 0:3] = z
        X[j, 9] = OMEGA0
        for i in range(3):
            Ps[j, i, i], Ps[j, 3 + i, 3 + i], Ps[j, 6 + i, 6 + i] = R, V0 * V0, A0 * A0
        Ps[j, 9, 9] = OMEGA_SD0 ** 2
    return X, Ps, MU0.copy()
