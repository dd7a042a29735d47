"""``estimator: auto`` — an interacting-multiple-model (IMM) filter of one object's motion.

It sees only the camera's samples [stamp, x, y, z, valid] (never the target's kind or
parameters) and the camera's stated noise_std, rate and latency.  All models share one
state, χ = [p (3), v (3), a (3), Ω] (10 values; Ω = ω² ≥ 0, rad²/s²), with a full 10×10
covariance, so mixing needs no padding:

- ``cv`` (constant velocity, white acceleration q = Q_CV): p ← p + vΔ, v ← v, a ← 0 with
  variance A_CV² (unused by the model, kept so the mixed covariance stays definite);
- ``ca`` (constant acceleration, white jerk q = Q_CA): a belt that speeds up;
- ``turn`` (3-D constant angular rate: ȧ = −Ω v, white jerk q = Q_TURN, Ω a random walk of
  density Q_OMEGA): the exact model of any harmonic ellipse or circle, in any plane
  (the paper's curve, eq. 28, is one with Ω = 1.5² = 2.25); with Ω = 0 it is ``ca``.
  Over Δ, with ω = √Ω, s = sin(ωΔ)/ω, c = cos(ωΔ), r = (1 − c)/Ω:
  p ← p + s v + r a,  v ← c v + s a,  a ← −Ω s v + c a  (series for small ωΔ); the
  Jacobian in Ω is a forward difference (an extended Kalman filter); Ω is clipped to
  [0, OMEGA_MAX];
- ``fall`` (free flight: ``cv`` plus the world's gravity GRAVITY, white acceleration
  q = Q_FALL): a thrown object.  Gravity is a property of the world the camera is
  calibrated in, not of the target: the estimator is told nothing about what it sees.

Each of the three axes is measured: z = p + ν, R = max(noise_std², R_MIN) I₃.
One IMM cycle at a new sample (measurement time t_m, Δ = t_m − t_est):
mixing c_j = Σᵢ Πᵢⱼ μᵢ, μᵢ|ⱼ = Πᵢⱼ μᵢ / c_j, χ⁰ⱼ = Σᵢ μᵢ|ⱼ χᵢ,
P⁰ⱼ = Σᵢ μᵢ|ⱼ (Pᵢ + (χᵢ − χ⁰ⱼ)(χᵢ − χ⁰ⱼ)ᵀ); each model predicts and corrects (Joseph form),
its likelihood is N(y; 0, S); μⱼ ∝ c_j N(y; 0, S) (in logs).  Π: stay with probability
exp(−Δ/SOJOURN), else switch to either other model.  A dropout (no new sample at an
update) mixes and predicts only (μⱼ = c_j).  The timing (latency compensation, priming
with pre-run samples, update instants) is ``kalman.TargetKalmanFilter``'s.

Output ``target`` (9) = [p̂ + v̂Δt + âΔt²/2, v̂ + âΔt, â] of the combined estimate
χ̂ = Σ μⱼ χⱼ, Δt = t − t_est (the same layout as the Kalman filter); ``probabilities`` (4, μ of ``MODELS``).

Why these models and constants (chosen by measurement: open loop on camera samples of the
bundled motions, the filter floor of ``study camera --filter-floor``, and closed loop over
seeds 1–10 at 2 mm / 30 Hz / 33 ms; docs/camera.md has the tables).  The hand-set
scenarios needed one q per motion (1e-6 on belts, 3e-4 on a speed-up, 0.03 on the curve);
an IMM runs such models side by side and weighs them by how well each predicted the last
sample.  Measured against the best hand-set filter of each motion (median over seeds of
the largest open-loop error after tf): belts 1.30 mm (kalman_cv 1e-6: 1.36), the curve
2.9 mm (kalman_ca 0.03: 6.7 — the turn model follows the ellipse with a small jerk noise
once Ω is learnt, a constant-acceleration model needs a large one and passes the noise
through), a lob at 60 Hz 2.4 mm (kalman_ca: 3.6 — a free-flight model fits 6 numbers, not
9, to the ~20 samples of a short flight); the belt that speeds up is the one motion where
it is behind (4.5 mm against 3.2 for kalman_cv 3e-4).  SOJOURN = 20 s: at 1 s the
models mix so often that the belts' error doubles (2.9 mm rms against 0.9).  A library
(filterpy, stonesoup) was not needed: the filter is ~200 lines and its whole state lives
in the context.  Each equation is one compiled kernel (numba, ``@njit(cache=True)``; a model
is selected by its code, its index in ``MODELS``; small matrix products as loops, S⁻¹ of the
3×3 S by its adjugate).  Cost: about 20–35 µs per camera sample from Python (four 10-state
extended Kalman steps and the mixing; the numpy version took 0.5–1 ms), 13–20 µs for a
cycle without a sample; compiling the kernels cold takes ~15 s (``warm_up``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.camera import TIME_TOL, MeasurementConfig, validate_measurement

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
    """One IMM cycle over dt, correcting with the position z (3; ``NO_SAMPLE``, empty: predict
    only): (X, Ps, μ) after it, μⱼ ∝ c_j N(y; 0, S) (in logs; μⱼ = c_j without a sample)."""
    X0, P0, c = mix(X, Ps, mu, dt)
    logs = np.zeros(len(MODELS))
    for j in range(len(MODELS)):
        X0[j], P0[j] = predict_model(j, X0[j], P0[j], dt)
        if len(z) != 0:
            X0[j], P0[j], logs[j] = correct(X0[j], P0[j], z, R)
    logw = np.log(np.maximum(c, 1e-300)) + logs
    w = np.exp(logw - logw.max())
    return X0, P0, w / w.sum()


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


class AdaptiveTargetEstimator(LeafSystem):
    """The IMM filter of one object's motion as a Drake system (``estimator: auto``).

    Input port ``measurement`` (5): [stamp, x, y, z, valid] from a ``Camera``.
    Output ports ``target`` (9): [p, v, a] of the combined estimate predicted to t (zeros
    before the first sample); ``probabilities`` (4): μ of ``MODELS``; ``polynomial`` (28): the
    state of that name (``target_prediction.PolynomialTargetSelector`` evaluates it in C++).
    Discrete state groups (``groups`` maps the names to indices): ``meta`` = [initialised,
    t_est, last stamp consumed, t of the last update], ``estimates`` = χⱼ (4×10 row-major),
    ``covariances`` = Pⱼ (4×10×10), ``probabilities`` = μ (4), ``polynomial`` = [t_est, c₀, c₁,
    c₂] (1 + 3·9: the output is c₀ + Δt c₁ + Δt² c₂, zeros before the first sample), stored at
    each update from χ̂ = Σ μⱼ χⱼ so that an evaluation of the output only extrapolates.
    ``prior``: pre-run samples [(t_k, z_k), …] consumed as in ``TargetKalmanFilter``.
    """

    def __init__(self, *, config: MeasurementConfig, prior=None):
        super().__init__()
        validate_measurement(config)
        self._R = max(float(config.noise_std) ** 2, R_MIN)
        self._latency = float(config.latency)
        self._compensate = bool(config.compensate_latency)
        self._z_in = self.DeclareVectorInputPort("measurement", 5)
        state = self._prior_state(prior)
        self.groups = {name: self.DeclareDiscreteState(value.ravel())
                       for name, value in zip(("meta", "estimates", "covariances", "probabilities"),
                                              state)}
        self.groups["polynomial"] = self.DeclareDiscreteState(_polynomial(state[0], state[3] @ state[1]))
        self.DeclarePeriodicDiscreteUpdateEvent(1.0 / config.rate_hz, self._latency, self._update)
        ticket = {self.time_ticket(), self.xd_ticket()}
        self._target_out = self.DeclareVectorOutputPort(
            "target", 9, lambda c, o: o.SetFromVector(self._predict_target(c)),
            prerequisites_of_calc=ticket)
        self._polynomial_out = self.DeclareStateOutputPort("polynomial", self.groups["polynomial"])
        self._mu_out = self.DeclareVectorOutputPort(
            "probabilities", len(MODELS),
            lambda c, o: o.SetFromVector(c.get_discrete_state(self.groups["probabilities"]).value()),
            prerequisites_of_calc={self.xd_ticket()})

    def get_measurement_input_port(self):
        return self._z_in

    def get_target_output_port(self):
        return self._target_out

    def get_polynomial_output_port(self):
        """The ``polynomial`` state on a C++ port (``target_prediction``)."""
        return self._polynomial_out

    def get_probabilities_output_port(self):
        return self._mu_out

    def state(self, context) -> tuple:
        """(meta, X as 4×10, Ps as 4×10×10, μ) from a context (copies)."""
        value = [context.get_discrete_state(self.groups[name]).value().copy()
                 for name in ("meta", "estimates", "covariances", "probabilities")]
        m = len(MODELS)
        return value[0], value[1].reshape(m, N), value[2].reshape(m, N, N), value[3]

    def step(self, meta, X, Ps, mu, t: float, z: np.ndarray):
        """One update at time t with the camera's output z: (meta, X, Ps, μ) after it, or None
        when nothing changes (no sample seen yet).  ``TargetKalmanFilter.step``'s timing."""
        initialised, t_est, last_stamp, _ = meta
        stamp = z[0]
        if z[4] > 0.5 and (initialised < 0.5 or stamp > last_stamp + TIME_TOL):
            t_meas = stamp if self._compensate else t
            if initialised < 0.5:
                X, Ps, mu = initial_state(z[1:4], self._R)
            else:
                X, Ps, mu = imm_cycle(X, Ps, mu, max(t_meas - t_est, 0.0), z[1:4], self._R)
            return np.array([1.0, t_meas, stamp, t]), X, Ps, mu
        if initialised < 0.5:
            return None
        t_pred = t - self._latency if self._compensate else t
        X, Ps, mu = imm_cycle(X, Ps, mu, max(t_pred - t_est, 0.0), NO_SAMPLE, self._R)
        return np.array([1.0, max(t_pred, t_est), last_stamp, t]), X, Ps, mu

    def _update(self, context, discrete_state) -> None:
        result = self.step(*self.state(context), context.get_time(), self._z_in.Eval(context))
        if result is None:
            return
        for name, value in zip(("meta", "estimates", "covariances", "probabilities"), result):
            discrete_state.get_mutable_vector(self.groups[name]).SetFromVector(value.ravel())
        discrete_state.get_mutable_vector(self.groups["polynomial"]).SetFromVector(
            _polynomial(result[0], result[3] @ result[1]))

    def _prior_state(self, prior) -> tuple:
        """The state at t = 0 after the pre-run samples, each consumed when it became visible."""
        m = len(MODELS)
        state = (np.zeros(4), np.zeros((m, N)), np.tile(np.eye(N), (m, 1, 1)), MU0.copy())
        for t_k, z_k in prior or []:
            t_seen = t_k + self._latency
            if t_seen > TIME_TOL:
                raise ValueError(f"prior: a sample taken at {t_k} s is not visible before t = 0")
            result = self.step(*state, t_seen, np.array([t_k, *z_k, 1.0]))
            if result is not None:
                state = result
        return state

    def _predict_target(self, context) -> np.ndarray:
        """[p + vΔt + aΔt²/2, v + aΔt, a] of Σ μⱼ χⱼ, Δt = t − t_est (zeros before a sample)."""
        c = context.get_discrete_state(self.groups["polynomial"]).value()
        dt = context.get_time() - c[0]
        return c[1:10] + dt * c[10:19] + (dt * dt) * c[19:28]


def _polynomial(meta: np.ndarray, x: np.ndarray) -> np.ndarray:
    """[t_est, c₀, c₁, c₂] of the output c₀ + Δt c₁ + Δt² c₂ = [p + vΔt + aΔt²/2, v + aΔt, a]
    for the combined estimate x = χ̂ (all zeros before the first sample, meta[0] = 0).  The
    same floating-point numbers as the formula: a halved is exact, and the added zeros are."""
    if meta[0] < 0.5:
        return np.zeros(28)
    p, v, a = x[0:3], x[3:6], x[6:9]
    return np.concatenate([[meta[1]], p, v, a, v, a, np.zeros(3), 0.5 * a, np.zeros(6)])
