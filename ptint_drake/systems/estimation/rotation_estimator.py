"""Tracking an object's orientation from its camera (issue 21): ``RotationEstimator``.

It sees only the camera's orientation samples [stamp, Z (row-major), valid]
(``camera.Camera`` with ``rotation``) and the camera's stated ``rot_noise_deg``, rate and
latency — never the target's kind, orientation or rate.  Every camera estimator setting
(``auto`` and the hand-set position filters alike) gets it: there is nothing to choose.

Model: an error-state (multiplicative) Kalman filter on SO(3).  The state is a reference
rotation R̂ (world frame) and the world-frame angular velocity ω̂; the object's rotation is
R = exp([δθ]×) R̂ with a small world-frame error δθ.  The motion is a constant angular
velocity driven by white angular acceleration of spectral density Q_SPIN (rad²/s³), per
axis and identical on the three axes, so the error state per axis is χ = [δθ, ω] with
``kalman``'s constant-velocity F(Δ) and Q(Δ) and one 2×2 covariance P shared by the axes
(the camera's noise is isotropic: R_θ = σ_R² per axis, σ_R = rot_noise_deg in rad).

    predict over Δ:  R̂ ← exp([ω̂ Δ]×) R̂   (exact for a constant world-frame ω),
                     P ← F P Fᵀ + Q
    correct with Z:  y = log(Z R̂ᵀ)^∨ (the shorter rotation), K = P Hᵀ / (P₀₀ + R_θ),
                     [δθ; ω̂] ← K y (per axis), R̂ ← exp([δθ]×) R̂, δθ ← 0,
                     P ← (I − K H) P (I − K H)ᵀ + R_θ K Kᵀ   (Joseph form)

The exponential is ``orientation.rotation_exp_of`` (Rodrigues, compiled: the output is evaluated at
every derivative evaluation of a run, where Drake's ``AngleAxis`` cost 8 µs a call) and the log
``orientation.rotation_log``, the compiled log the controller and the metrics use too; R̂ is
re-projected onto SO(3) (Drake's ``ProjectToRotationMatrix``) at every update.  The timing — update
instants at the camera's rate offset by its latency, the latency compensated by
predicting from the sample's stamp, predict-only during dropouts, priming with the pre-run
samples — is ``sampled_estimator.SampledEstimator``'s.  The first sample sets R̂ = Z, ω̂ = 0,
P₀ = diag(R_θ, W0²).

Output ``target_rotation`` (15, ``signals.TARGET_ROTATION``) = [exp([ω̂ Δt]×) R̂ (row-major),
ω̂, 0] with Δt = t − t_est: continuous between updates, the interceptor's layout (ω̇_r = 0:
the model's); an unturned, fixed frame before the first sample.

Why constant angular velocity and Q_SPIN (chosen by measurement, camera and estimator alone:
30 Hz, 1°, 33 ms; docs/camera.md has the table): a part at rest on a belt (conveyor_yaw) and
a frame turning at a constant rate (curve_pose, 36°/s about a tilted axis) are both exactly
this model, so neither lags; Q_SPIN only weighs how fast a change of rate is followed
against how much noise passes.  A constant-angular-acceleration model passed more noise on
both for no gain.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit
from pydrake.math import RotationMatrix
from pydrake.systems.framework import DiagramBuilder, OutputPort

from ptint_drake.systems.estimation.kalman import process_covariance, transition
from ptint_drake.systems.estimation.sampled_estimator import SampledEstimator
from ptint_drake.systems.estimation.target_prediction import ActiveTargetSelector
from ptint_drake.systems.perception.camera import MeasurementConfig, rotation_noise
from ptint_drake.systems.task.orientation import ROTATION_WIDTH, rotation_exp, rotation_log, rotation_row
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET_ROTATION_SIZE

Q_SPIN = 1.0e-3  # rad²/s³, white angular acceleration
W0 = 1.0  # rad/s, initial angular-velocity standard deviation
R_MIN = 1.0e-12  # rad², floor of the measurement variance
_H = np.array([1.0, 0.0])
MEASURED_ROTATION_SIZE = 11  # [stamp, Z row-major, valid]


def _turned(R: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """exp([φ]×) R (3×3 arrays)."""
    return rotation_exp(phi) @ R


@njit(cache=True)
def predicted_rotation(t: float, meta, R, w, out) -> None:
    """``out`` (15) ← [exp([ω̂ Δt]×) R̂ (row-major), ω̂, 0], Δt = t − t_est, from the filter's
    ``meta`` [initialised, t_est, …], R̂ (row-major, 9) and ω̂ (``orientation.rotation_row`` of
    [R̂, ω̂] at Δt); an unturned, fixed frame before the first sample."""
    if meta[0] < 0.5:
        out[:] = 0.0
        out[0] = out[4] = out[8] = 1.0
        return
    c = np.empty(ROTATION_WIDTH)  # the filter's state as a compiled spinning orientation
    c[0:9], c[9:12] = R, w
    rotation_row(c, t - meta[1], out)


class RotationEstimator(SampledEstimator):
    """The orientation filter of one object (see the module docstring).

    Input port ``measured_rotation`` (11): [stamp, Z row-major, valid] from a ``Camera``.
    Output port ``target_rotation`` (15): [R, ω, ω̇] predicted to t.
    Discrete state groups (``groups``): ``meta`` = [initialised, t_est, last stamp consumed,
    t of the last update], ``rotation`` = R̂ (row-major), ``rate`` = ω̂ (3), ``covariance`` =
    P (2×2 row-major) at t_est.
    ``prior``: the camera's pre-run orientation samples [(t_k, Z_k), …]
    (``Camera.pre_run_rotations()``), consumed as ``SampledEstimator`` consumes a prior.
    """

    def __init__(self, *, config: MeasurementConfig, prior=None, q: float = Q_SPIN):
        super().__init__(config=config, input_name="measured_rotation", input_size=MEASURED_ROTATION_SIZE)
        self._R = max(rotation_noise(config) ** 2, R_MIN)
        self._q = float(q)
        self._declare_state(("rotation", "rate", "covariance"), prior)
        self._out = self.DeclareVectorOutputPort(
            "target_rotation", TARGET_ROTATION_SIZE, self._calc_prediction,
            prerequisites_of_calc={self.time_ticket(), self.xd_ticket()})
        self._meta, self._rotation, self._rate = (self.groups[k] for k in ("meta", "rotation", "rate"))

    @property
    def measurement_variance(self) -> float:
        """R_θ (rad²) per axis."""
        return self._R

    def get_measured_rotation_input_port(self):
        return self._z_in

    def get_target_rotation_output_port(self):
        return self._out

    def _initial_estimate(self) -> tuple:
        """R̂ = I, ω̂ = 0, P₀ = diag(R_θ, W0²)."""
        return np.eye(3), np.zeros(3), np.diag([self._R, W0 * W0])

    def _first_estimate(self, z: np.ndarray) -> tuple:
        """R̂ = Z (projected onto SO(3)), ω̂ = 0, P₀."""
        _, w, P = self._initial_estimate()
        return RotationMatrix.ProjectToRotationMatrix(np.reshape(z[1:10], (3, 3))).matrix(), w, P

    def _predicted(self, estimate: tuple, dt: float) -> tuple:
        """R̂ ← exp([ω̂ Δ]×) R̂, P ← F P Fᵀ + Q."""
        R, w, P = estimate
        F = transition("cv", dt)
        P = F @ P @ F.T + process_covariance("cv", dt, self._q)
        return _turned(R, w * dt), w, 0.5 * (P + P.T)

    def _corrected(self, estimate: tuple, dt: float, z: np.ndarray) -> tuple:
        """Predicted over dt, then corrected with Z: y = log(Z R̂ᵀ)^∨, [δθ; ω̂] ← K y, Joseph form."""
        R, w, P = self._predicted(estimate, dt)
        y = rotation_log(np.reshape(z[1:10], (3, 3)) @ R.T)
        K = P[:, 0] / (P[0, 0] + self._R)
        R = RotationMatrix.ProjectToRotationMatrix(_turned(R, K[0] * y)).matrix()
        A = np.eye(2) - np.outer(K, _H)
        P = A @ P @ A.T + self._R * np.outer(K, K)
        return R, w + K[1] * y, 0.5 * (P + P.T)

    def _calc_prediction(self, context, output) -> None:
        """``target_rotation``: ``predicted_rotation`` of the state at t, into the output."""
        xd = context.get_discrete_state()
        predicted_rotation(context.get_time(), xd.get_vector(self._meta).value(),
                           xd.get_vector(self._rotation).value(), xd.get_vector(self._rate).value(),
                           output.get_mutable_value())


@dataclass
class RotationEstimators:
    """What ``AddRotationEstimators`` added: wire ``rotation_port`` to a controller's
    ``target_rotation``."""

    rotation_port: OutputPort
    filters: list
    selector: ActiveTargetSelector


def AddRotationEstimators(builder: DiagramBuilder, *, cameras: list, schedule: Schedule,
                          config: MeasurementConfig) -> RotationEstimators:
    """Add, per camera i (one per object, measuring orientations: ``Camera(rotation=True)``,
    e.g. ``kalman.AddCameraEstimators``' with ``rotations_port``), ``rotation_filter_i`` primed
    with its pre-run samples, and ``rotation_selector`` passing on the active segment's."""
    if not all(camera.measures_rotation for camera in cameras):
        raise ValueError("cameras: every camera must measure the orientation (Camera(rotation=True))")
    selector = builder.AddNamedSystem("rotation_selector", ActiveTargetSelector(
        schedule=schedule, count=len(cameras), size=TARGET_ROTATION_SIZE))
    filters = []
    for i, camera in enumerate(cameras):
        f = builder.AddNamedSystem(f"rotation_filter_{i}", RotationEstimator(
            config=config, prior=camera.pre_run_rotations()))
        builder.Connect(camera.get_measured_rotation_output_port(), f.get_measured_rotation_input_port())
        builder.Connect(f.get_target_rotation_output_port(), selector.get_input_port(i))
        filters.append(f)
    return RotationEstimators(selector.get_target_output_port(), filters, selector)
