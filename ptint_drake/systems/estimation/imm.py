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
update) *coasts*: each model predicts its own χⱼ, Pⱼ, unmixed, and μ is held (below).  The
timing (latency compensation, priming with pre-run samples, update instants) is
``sampled_estimator.SampledEstimator``'s.

Through a gap (the arm hiding the object for its last frames, a dropout window) the
estimate is the filter's prediction conditioned on no switch since the last sample:
Σ μⱼ χⱼ with each χⱼ predicted by its own model and μ as the last sample left it.  The
textbook cycle without a sample (mixing, then μ ← Πᵀμ; Blom & Bar-Shalom 1988, Bar-Shalom,
Li & Kirubarajan 2001 §11.6) applies the switching prior with nothing to test it: repeated
over a gap it moves μ toward Π's stationary distribution (uniform) by about Δ/(3·SOJOURN)
per cycle, and the combined mean then weighs in models whose predictions leave the data
quadratically — ``fall`` drops ½gT², 1.08 m after T = 0.47 s.  On conveyor_pair_rgbd (seed 0;
the tool hides box 1 from 1.73 s to its tf at 2.2 s) μ_fall rose from 2e-5 to 0.008 and
the combined estimate sank with −0.08 m/s² (g·μ_fall): 3.8 mm low at tf, 10 mm at 2.37 s
(segment 1: e(tf) 4.6 mm, hold 66 mm).  SOJOURN is a tracking rate (how fast samples may
re-weigh the models, chosen by measurement below), not a measured switching rate of the
objects, so its drift carries no information about the hidden motion; a motion that did
change in the gap shows at the next sample as an innovation of many σ (a belt that stopped
for 0.5 s: 40 mm against σ ≈ 0.5 mm), whose likelihoods re-weigh μ at once, and the
switching resumes with that sample.  Nothing here is a constant: with one model dominant,
coasting is that model's own prediction, and a real acceleration (a throw: ``fall``; a belt
speeding up: ``ca``) is extrapolated through the gap exactly as far as its model carries it.

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
in the context.  Each equation is one compiled kernel (``imm_kernels``: numba; a model
is selected by its code, its index in ``MODELS``; small matrix products as loops, S⁻¹ of the
3×3 S by its adjugate).  Cost: about 20–35 µs per camera sample from Python (four 10-state
extended Kalman steps and the mixing; the numpy version took 0.5–1 ms), 13–20 µs for a
cycle without a sample; compiling the kernels cold takes ~15 s (``warm_up``).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.systems.estimation.imm_kernels import (MODELS, MU0, NO_SAMPLE, R_MIN, N, imm_cycle,
                                                        initial_state)
from ptint_drake.systems.estimation.sampled_estimator import SampledEstimator
from ptint_drake.systems.perception.camera import MeasurementConfig


class AdaptiveTargetEstimator(SampledEstimator):
    """The IMM filter of one object's motion as a Drake system (``estimator: auto``).

    Input port ``measurement`` (5): [stamp, x, y, z, valid] from a ``Camera``.
    Output ports ``target`` (9): [p, v, a] of the combined estimate predicted to t (zeros
    before the first sample); ``probabilities`` (4): μ of ``MODELS``; ``polynomial`` (28): the
    state of that name (``target_prediction.ActiveTargetSelector`` evaluates it, compiled).
    Discrete state groups (``groups`` maps the names to indices): ``meta`` = [initialised,
    t_est, last stamp consumed, t of the last update], ``estimates`` = χⱼ (4×10 row-major),
    ``covariances`` = Pⱼ (4×10×10), ``probabilities`` = μ (4), ``polynomial`` = [t_est, c₀, c₁,
    c₂] (1 + 3·9: the output is c₀ + Δt c₁ + Δt² c₂, zeros before the first sample), stored at
    each update from χ̂ = Σ μⱼ χⱼ so that an evaluation of the output only extrapolates.
    ``prior``: pre-run samples [(t_k, z_k), …] consumed as ``SampledEstimator`` consumes them.
    """

    def __init__(self, *, config: MeasurementConfig, prior=None):
        super().__init__(config=config, input_name="measurement", input_size=5)
        self._R = max(float(config.noise_std) ** 2, R_MIN)
        self._declare_state(("estimates", "covariances", "probabilities"), prior)
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

    def _initial_estimate(self) -> tuple:
        """X = 0 (4×10), Ps = I (4×10×10), μ = MU0."""
        m = len(MODELS)
        return np.zeros((m, N)), np.tile(np.eye(N), (m, 1, 1)), MU0.copy()

    def _first_estimate(self, z: np.ndarray) -> tuple:
        return initial_state(z[1:4], self._R)

    def _corrected(self, estimate: tuple, dt: float, z: np.ndarray) -> tuple:
        """One IMM cycle with the sample: mixing, each model's prediction and correction, μ."""
        return imm_cycle(*estimate, dt, z[1:4], self._R)

    def _predicted(self, estimate: tuple, dt: float) -> tuple:
        """One IMM cycle without a sample: mixing and prediction, μⱼ = c_j."""
        return imm_cycle(*estimate, dt, NO_SAMPLE, self._R)

    def _derived(self, state: tuple) -> dict:
        """``polynomial`` of the combined estimate χ̂ = Σ μⱼ χⱼ."""
        return {"polynomial": _polynomial(state[0], state[3] @ state[1])}

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
