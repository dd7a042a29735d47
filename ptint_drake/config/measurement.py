"""How the target is observed (the scenario's ``measurement`` block); the camera and the
estimators that read it live in ``systems.camera``, ``systems.kalman`` and ``systems.imm``.
(No postponed annotations: Drake's ``yaml_load_typed`` reads the types.)"""

from dataclasses import dataclass, field
from typing import Optional

@dataclass
class MeasurementConfig:
    """How the target is observed (scenario key ``measurement``; absent: no camera, the
    controller is given the analytic target, the paper's setting).

    ``estimator``: ``auto`` (default; ``imm.AdaptiveTargetEstimator``, nothing to tune),
    or a hand-set Kalman filter ``kalman_cv`` / ``kalman_ca`` whose ``process_noise`` is
    the spectral density q of its white acceleration (m²/s³) or jerk (m²/s⁵), default
    DEFAULT_PROCESS_NOISE = 0.01 (``kalman``'s docstring has the numbers); ``none``: no
    camera, only with a perfect one (noise, latency and dropouts all 0).  ``rot_noise_deg``: the
    orientation samples' noise, for objects with an orientation (``Camera(rotation=True)``).
    """

    noise_std: float = 0.0  # m, per axis
    rate_hz: float = 30.0  # samples per second
    latency: float = 0.0  # s, from taking a sample to seeing it
    compensate_latency: bool = True  # the filter predicts over the latency
    dropouts: list[list[float]] = field(default_factory=list)  # [from, to] windows, s
    seed: int = 0
    estimator: str = "auto"  # auto | kalman_cv | kalman_ca | none
    # q of the hand-set filters: m²/s³ (kalman_cv) or m²/s⁵ (kalman_ca); None: 0.01
    process_noise: Optional[float] = None
    # s: how long the camera had each object in view before t = 0 (samples at
    # −prior_window ≤ t_k < 0); used when the camera is given the object's motion
    # before the run (the simulation does); 0: nothing is seen before t = 0
    prior_window: float = 1.0
    rot_noise_deg: Optional[float] = None  # deg per axis of an orientation sample's noise; None: 1


