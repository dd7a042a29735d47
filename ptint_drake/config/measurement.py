"""How the target is observed (the scenario's ``measurement`` block); the camera and the
estimators that read it live in ``systems.perception.camera``, ``systems.estimation.kalman``
and ``systems.estimation.imm``.
(No postponed annotations: Drake's ``yaml_load_typed`` reads the types.)"""

from dataclasses import dataclass, field
from typing import List, Optional

SENSORS = ("pose", "rgbd")


@dataclass
class BeltRegionConfig:
    """A conveyor's top surface as the RGB-D perception knows it (configured geometry, not the
    simulator's): a horizontal rectangle centred at ``center``, long along ``direction``."""

    center: List[float] = field(default_factory=lambda: [0.3, 0.0, 0.1])  # m, top-surface centre
    direction: List[float] = field(default_factory=lambda: [0.0, 1.0, 0.0])  # horizontal unit vector
    length: float = 0.6  # m, along ``direction``
    width: float = 0.08  # m, across


@dataclass
class RgbdCameraConfig:
    """A rendered RGB-D camera fixed in the world (``measurement.sensor: rgbd``;
    ``systems.perception``).  Its pose: ``xyz`` + ``rpy_deg`` (Drake's camera frame: +z the
    optical axis, +x right, +y down in the image), or ``look_at`` + ``look_from`` (``from`` is a
    Python keyword: the key is ``look_from``; image down is as close to world −z as it can be)."""

    width: int = 640  # pixels
    height: int = 480  # pixels
    fov_y_deg: float = 45.0  # deg, vertical field of view
    xyz: Optional[list[float]] = None  # m, camera origin in world
    rpy_deg: Optional[list[float]] = None  # deg, camera frame's roll-pitch-yaw in world
    look_at: Optional[list[float]] = None  # m, a world point on the optical axis
    look_from: Optional[list[float]] = None  # m, the camera origin (with look_at)
    # × the RealSense D415-style depth noise (systems.perception.depth_noise); 0: noiseless
    depth_noise_scale: float = 1.0
    part_shape: str = "box"  # the parts' known shape: "box" or "cylinder" (axis vertical)
    # m, box [x, y, z] or cylinder [diameter, height]; the interception world's objects' size
    part_size: List[float] = field(default_factory=lambda: [0.03, 0.03, 0.03])
    # the conveyors' top surfaces; empty: the world derives one under each object's path
    belts: List[BeltRegionConfig] = field(default_factory=list)
    # calibration error: [dx, dy, dz (m), droll, dpitch, dyaw (deg)] of the real camera from its
    # configured pose, in the camera frame; the image is rendered there while the perception
    # believes the configured pose (``robust`` draws it); empty: none
    pose_error: List[float] = field(default_factory=list)

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
    # "pose": the formula above (true pose + noise); "rgbd": a rendered depth camera and the
    # part poses fitted to its point clouds (``camera``; noise_std and rot_noise_deg unused)
    sensor: str = "pose"
    camera: Optional[RgbdCameraConfig] = None  # with sensor: rgbd


