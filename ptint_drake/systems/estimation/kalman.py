"""Estimating a target's motion from camera samples, and choosing the active one.

``TargetKalmanFilter`` — a time-varying discrete Kalman filter per object.

Model (per axis; the three axes are independent and identical): state
χ = [p, v] (``"cv"``, constant velocity driven by white acceleration) or
χ = [p, v, a] (``"ca"``, constant acceleration driven by white jerk), with
spectral density q = ``process_noise``.  Over a step Δ:

    cv:  F = [[1, Δ], [0, 1]],            Q = q [[Δ³/3, Δ²/2], [Δ²/2, Δ]]
    ca:  F = [[1, Δ, Δ²/2], [0, 1, Δ], [0, 0, 1]],
         Q = q [[Δ⁵/20, Δ⁴/8, Δ³/6], [Δ⁴/8, Δ³/3, Δ²/2], [Δ³/6, Δ²/2, Δ]]
    measurement z = H χ + ν,  H = [1, 0(, 0)],  R = max(noise_std², R_MIN),  R_MIN = (1 µm)²

    predict:  χ ← F χ,  P ← F P Fᵀ + Q
    correct:  S = H P Hᵀ + R,  K = P Hᵀ / S,  χ ← χ + K (z − H χ),
              P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ    (Joseph form: stays symmetric PSD)

The axes share F, Q, R, P₀ and the measurement times, so their covariances are equal:
the filter keeps one n×n P (n = 2 or 3) and an n×3 estimate (one column per axis).

Timing and priming are ``sampled_estimator.SampledEstimator``'s (the rule every camera
estimator shares: an update when the camera's sample k becomes visible, predict and
correct at a new sample, predict only in a dropout, the pre-run samples consumed before
t = 0).  The first valid sample initialises χ = [z, 0(, 0)], P₀ = diag(R, V0², A0²) with
V0 = 1 m/s and A0 = 10 m/s² (large against the targets here, ≤ 0.2 m/s, ≤ 0.3 m/s²).

Output ``target`` (9) = [p̂ + v̂Δt + âΔt²/2,  v̂ + âΔt,  â] with Δt = t − t_est, t_est
the time the estimate refers to: continuous in t between updates (for ``cv`` â = 0);
with ``compensate_latency`` Δt includes the latency, so the prediction removes the
lag of a delayed sample.  Zeros until the first sample is seen.
Output ``covariance`` (n²): P predicted to t (F(Δt) P F(Δt)ᵀ + Q(Δt)), row-major,
for figures (P[0, 0] is the variance of each axis' position; P₀ before the first sample).

Discrete state, three groups: ``meta`` = [initialised, t_est, last stamp consumed,
t of the last update], ``estimate`` = χ as n×3 row-major ([p_xyz, v_xyz(, a_xyz)]),
``covariance`` = P (n×n row-major) at t_est.

Default ``process_noise`` q = 0.01 (see ``camera.MeasurementConfig``), chosen on the
paper's curve (0.1 m amplitude, 1.5 rad/s: |a| ≤ 0.23 m/s², |ȧ| ≤ 0.34 m/s³) seen at
30 Hz, sweeping q over 1e-4 … 100: it gave the smallest error of both models for
noise_std 0.1 mm and 0.5 mm.  Steady RMS of |output − truth| (t = 2 … 6 s, latency 0):

    noise_std   cv: position / velocity     ca: position / velocity
    0.1 mm      0.35 mm / 12.5 mm/s         0.20 mm / 4.2 mm/s
    0.5 mm      1.08 mm / 22 mm/s           0.78 mm / 10 mm/s
    0           0.13 mm / 8 mm/s (lag)      0.006 mm / 0.4 mm/s

A constant-velocity conveyor is tracked without bias by both models (smaller q only
smooths more).  q = 0.001 or 0.1 raises the errors above by up to 1.7×; q = 1e-4
lags by millimetres on the curve.  Closed-loop
tuning (what the interceptor tolerates) is left to the scenarios.

The best hand-set q per motion (30 Hz, 2 mm, 33 ms compensated), closed loop over seeds
1–10 — what the camera scenarios used before ``estimator: auto`` (``imm``) made tuning
unnecessary, and the hand-set rows docs/camera.md compares ``auto`` with (steady-state per-axis
position std from the DARE):

- constant-speed conveyors, ``kalman_cv`` q = 1e-6 m²/s³ (the belt speed may wander
  √(q·1 s) = 1 mm/s per second): 0.55 mm per axis; q = 1e-5 → 0.72 mm and 1e-4 →
  0.94 mm gave medians of 1.2–1.6 mm at tf, over the 1.5 mm asked; q → 0 is still
  smaller on an exact line but leaves no room for any real change of speed;
- a conveyor whose speed doubles (0.06 → 0.12 m/s within ~0.2 s), ``kalman_cv``
  q = 3e-4: 1e-5 lags 8 mm at tf, 1e-4 and 1e-3 are 10–25 % worse than 3e-4;
- the paper's curve, ``kalman_ca`` q = 0.03 m²/s⁵ (jerk ≤ 0.34 m/s³): 1.27 mm per
  axis; 0.003 lags, 0.1–0.3 is noisier (open-loop RMS 3.3–3.7 mm against 3.1 mm).

``AddCameraEstimators`` wires a camera and an estimator per object and one
``target_prediction.ActiveTargetSelector`` passing on the active segment's estimate (``auto``: the
IMM of ``imm``, whose polynomials the selector evaluates, compiled; ``kalman_cv`` /
``kalman_ca``: this filter).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from pydrake.systems.framework import DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import Demultiplexer

from ptint_drake.systems.estimation.imm import AdaptiveTargetEstimator
from ptint_drake.systems.estimation.sampled_estimator import SampledEstimator
from ptint_drake.systems.estimation.target_prediction import ActiveTargetSelector
from ptint_drake.systems.perception.camera import (Camera, MeasurementConfig, process_noise,
                                                   validate_measurement)
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET_PORT_SIZE

MODELS = ("cv", "ca")
R_MIN = 1.0e-12  # m², floor of the measurement variance: (1 µm)²
V0 = 1.0  # m/s, initial velocity standard deviation
A0 = 10.0  # m/s², initial acceleration standard deviation


def model_order(model: str) -> int:
    """n, the per-axis state size: 2 for ``cv``, 3 for ``ca``."""
    if model not in MODELS:
        raise ValueError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    return 2 if model == "cv" else 3


def transition(model: str, dt: float) -> np.ndarray:
    """F(Δt), the per-axis state transition."""
    if model_order(model) == 2:
        return np.array([[1.0, dt], [0.0, 1.0]])
    return np.array([[1.0, dt, 0.5 * dt * dt], [0.0, 1.0, dt], [0.0, 0.0, 1.0]])


def process_covariance(model: str, dt: float, q: float) -> np.ndarray:
    """Q(Δt) of white acceleration (cv) or white jerk (ca) with spectral density q."""
    d2, d3 = dt * dt, dt * dt * dt
    if model_order(model) == 2:
        return q * np.array([[d3 / 3.0, d2 / 2.0], [d2 / 2.0, dt]])
    d4, d5 = d3 * dt, d3 * d2
    return q * np.array([[d5 / 20.0, d4 / 8.0, d3 / 6.0],
                         [d4 / 8.0, d3 / 3.0, d2 / 2.0],
                         [d3 / 6.0, d2 / 2.0, dt]])


def measurement_variance(config: MeasurementConfig) -> float:
    """R = max(noise_std², R_MIN)."""
    return max(float(config.noise_std) ** 2, R_MIN)


def initial_covariance(model: str, R: float) -> np.ndarray:
    """P₀ = diag(R, V0², A0²) (truncated to the model's order)."""
    return np.diag([R, V0 * V0, A0 * A0][:model_order(model)])


class TargetKalmanFilter(SampledEstimator):
    """Kalman filter of one object's motion from its camera (see the module docstring).

    Input port ``measurement`` (5): [stamp, x, y, z, valid] from a ``Camera``.
    Output ports ``target`` (9): [p, v, a] predicted to t; ``covariance`` (n²).
    Discrete state groups (``groups``): ``meta``, ``estimate`` (χ, n×3), ``covariance`` (P, n×n).

    ``prior``: the camera's samples seen before t = 0 (``Camera.pre_run_samples()``,
    [(t_k, z_k), …] oldest first); the default state is what the update rule makes of
    them, so the estimate is primed at t = 0 (no prior: zeros until a sample is seen).
    """

    def __init__(self, *, config: MeasurementConfig, model: str, prior=None):
        n = model_order(model)
        config = dataclasses.replace(config, estimator=f"kalman_{model}")  # this filter, whatever named
        super().__init__(config=config, input_name="measurement", input_size=5)
        self._n = n
        self._model = model
        self._config = config
        self._q = process_noise(config)
        self._R = measurement_variance(config)
        self._H = np.zeros(n)
        self._H[0] = 1.0
        self._declare_state(("estimate", "covariance"), prior)
        self._meta, self._estimate, self._covariance = self.groups.values()

        state_and_time = {self.time_ticket(), self.xd_ticket()}
        # ``target`` is read at every derivative evaluation; ``covariance`` (figures) only
        # costs when someone evaluates it
        self._target_out = self.DeclareVectorOutputPort(
            "target", TARGET_PORT_SIZE, lambda c, o: o.SetFromVector(self._predict_target(c)),
            prerequisites_of_calc=state_and_time)
        self._covariance_out = self.DeclareVectorOutputPort(
            "covariance", n * n, lambda c, o: o.SetFromVector(self._predict_covariance(c)),
            prerequisites_of_calc=state_and_time)

    @property
    def model(self) -> str:
        return self._model

    @property
    def order(self) -> int:
        """n, the per-axis state size."""
        return self._n

    @property
    def measurement_variance(self) -> float:
        return self._R

    def get_measurement_input_port(self):
        return self._z_in

    def get_target_output_port(self):
        return self._target_out

    def get_covariance_output_port(self):
        return self._covariance_out

    def gain(self, P_prior: np.ndarray) -> np.ndarray:
        """K = P Hᵀ / (H P Hᵀ + R) for an a-priori covariance P."""
        return P_prior[:, 0] / (P_prior[0, 0] + self._R)

    def _initial_estimate(self) -> tuple:
        """χ = 0 (n×3), P₀."""
        return np.zeros((self._n, 3)), initial_covariance(self._model, self._R)

    def _first_estimate(self, z: np.ndarray) -> tuple:
        """χ = [z, 0(, 0)], P₀."""
        X = np.zeros((self._n, 3))
        X[0] = z[1:4]
        return X, initial_covariance(self._model, self._R)

    def _predicted(self, estimate: tuple, dt: float) -> tuple:
        """χ ← F χ,  P ← F P Fᵀ + Q (symmetrised)."""
        X, P = estimate
        F = transition(self._model, dt)
        P = F @ P @ F.T + process_covariance(self._model, dt, self._q)
        return F @ X, 0.5 * (P + P.T)

    def _corrected(self, estimate: tuple, dt: float, z: np.ndarray) -> tuple:
        """Predicted over dt, then K = P Hᵀ / S, χ ← χ + K (z − H χ), P in Joseph form."""
        X, P = self._predicted(estimate, dt)
        K = self.gain(P)
        X = X + np.outer(K, z[1:4] - X[0])
        A = np.eye(self._n) - np.outer(K, self._H)
        P = A @ P @ A.T + self._R * np.outer(K, K)
        return X, 0.5 * (P + P.T)

    def _predict_target(self, context) -> np.ndarray:
        """[p + vΔt + aΔt²/2, v + aΔt, a], Δt = t − t_est (zeros before the first sample)."""
        meta = context.get_discrete_state(self._meta).value()
        if meta[0] < 0.5:
            return np.zeros(TARGET_PORT_SIZE)
        dt = context.get_time() - meta[1]
        X = context.get_discrete_state(self._estimate).value()
        if self._n == 2:
            return np.concatenate([X[0:3] + dt * X[3:6], X[3:6], np.zeros(3)])
        a = X[6:9]
        return np.concatenate([X[0:3] + dt * X[3:6] + (0.5 * dt * dt) * a, X[3:6] + dt * a, a])

    def _predict_covariance(self, context) -> np.ndarray:
        """F(Δt) P F(Δt)ᵀ + Q(Δt), row-major (P₀ before the first sample)."""
        n = self._n
        meta = context.get_discrete_state(self._meta).value()
        P = context.get_discrete_state(self._covariance).value().reshape(n, n)
        if meta[0] < 0.5:
            return P.ravel().copy()
        dt = context.get_time() - meta[1]
        F = transition(self._model, dt)
        return (F @ P @ F.T + process_covariance(self._model, dt, self._q)).ravel()


def _estimator(config: MeasurementConfig, prior) -> LeafSystem:
    """The estimator ``config.estimator`` names, primed with ``prior``."""
    if config.estimator == "auto":
        return AdaptiveTargetEstimator(config=config, prior=prior)
    return TargetKalmanFilter(config=config, model=config.estimator.split("_", 1)[1], prior=prior)


@dataclass
class CameraEstimators:
    """What ``AddCameraEstimators`` added: wire ``target_port`` to a controller's target."""

    target_port: OutputPort
    cameras: list
    filters: list
    selector: ActiveTargetSelector


def AddCameraEstimators(builder: DiagramBuilder, *, true_position_ports: list | None = None,
                        objects_port: OutputPort | None = None, schedule: Schedule,
                        config: MeasurementConfig, histories=None,
                        rotations_port: OutputPort | None = None, cameras: list | None = None
                        ) -> CameraEstimators:
    """Add, per object i, ``camera_i`` (seed_offset i) observing ``true_position_ports[i]``
    and ``target_filter_i``; and ``target_selector`` choosing the active one.  The handles
    returned hold every camera and filter (index i: object i).

    Or ``objects_port`` (3 per object, e.g. the station's ``objects``), split by ``object_positions``.
    ``histories`` (optional, one per object: a callable t → position or an object with
    ``evaluate``): the objects' true motion, so that each camera has also seen its object
    for ``config.prior_window`` s before t = 0 and its filter starts from those samples
    (priming); without it the cameras start seeing at t = 0.
    ``config.estimator``: ``auto`` (an ``imm.AdaptiveTargetEstimator`` per object, selected in C++
    by a polynomial ``ActiveTargetSelector``), or ``kalman_cv`` / ``kalman_ca`` (a ``TargetKalmanFilter``).
    ``rotations_port`` (9 per object, e.g. the station's ``object_rotations``): measured too.
    ``cameras`` (one per object, already in the diagram: e.g. ``perception.SeenObject``s of an
    RGB-D camera's fits): the samples come from them instead (no pose camera is added; pass
    ``true_position_ports`` as None and no ``objects_port``).
    """
    validate_measurement(config)
    if config.estimator not in ("auto", "kalman_cv", "kalman_ca"):
        raise ValueError("measurement.estimator: AddCameraEstimators needs auto, kalman_cv or "
                         f"kalman_ca, got {config.estimator!r}")
    if cameras is not None:
        return _estimators_of(builder, cameras, schedule, config)
    if (true_position_ports is None) == (objects_port is None):
        raise ValueError("AddCameraEstimators: give true_position_ports or objects_port, not both")
    if objects_port is not None:
        n = len(schedule.segments)
        split = builder.AddNamedSystem("object_positions", Demultiplexer([3] * n))
        builder.Connect(objects_port, split.get_input_port())
        true_position_ports = [split.get_output_port(i) for i in range(n)]
    if rotations_port is not None:
        rotations = builder.AddNamedSystem("object_rotations", Demultiplexer([9] * len(schedule)))
        builder.Connect(rotations_port, rotations.get_input_port())
    polynomial = config.estimator == "auto"
    selector = builder.AddNamedSystem("target_selector", ActiveTargetSelector(
        schedule=schedule, count=len(true_position_ports), polynomial=polynomial))
    if histories is not None and len(histories) != len(true_position_ports):
        raise ValueError(f"histories: one per object is needed, got {len(histories)} "
                         f"for {len(true_position_ports)} objects")
    cameras, filters = [], []
    for i, port in enumerate(true_position_ports):
        history = None if histories is None else histories[i]
        camera = builder.AddNamedSystem(f"camera_{i}", Camera(config=config, seed_offset=i, history=history,
                                                              rotation=rotations_port is not None))
        if rotations_port is not None:
            builder.Connect(rotations.get_output_port(i), camera.get_R_true_input_port())
        kf = builder.AddNamedSystem(f"target_filter_{i}", _estimator(config, camera.pre_run_samples()))
        builder.Connect(port, camera.get_x_true_input_port())
        builder.Connect(camera.get_measurement_output_port(), kf.get_measurement_input_port())
        get = kf.get_polynomial_output_port if polynomial else kf.get_target_output_port
        builder.Connect(get(), selector.get_input_port(i))
        cameras.append(camera)
        filters.append(kf)
    return CameraEstimators(selector.get_target_output_port(), cameras, filters, selector)


def _estimators_of(builder: DiagramBuilder, cameras: list, schedule: Schedule,
                   config: MeasurementConfig) -> CameraEstimators:
    """A filter per given camera (``AddCameraEstimators``' ``cameras``) and the selector."""
    polynomial = config.estimator == "auto"
    selector = builder.AddNamedSystem("target_selector", ActiveTargetSelector(
        schedule=schedule, count=len(cameras), polynomial=polynomial))
    filters = []
    for i, camera in enumerate(cameras):
        kf = builder.AddNamedSystem(f"target_filter_{i}", _estimator(config, camera.pre_run_samples()))
        builder.Connect(camera.get_measurement_output_port(), kf.get_measurement_input_port())
        get = kf.get_polynomial_output_port if polynomial else kf.get_target_output_port
        builder.Connect(get(), selector.get_input_port(i))
        filters.append(kf)
    return CameraEstimators(selector.get_target_output_port(), list(cameras), filters, selector)
