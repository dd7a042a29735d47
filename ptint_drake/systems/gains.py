"""The gains of the paper's controller and the choices it leaves open (paper section 3.1)."""

from dataclasses import dataclass


@dataclass
class ControllerGains:
    """The paper's gains (section 3.1) as defaults, and the choices it leaves open.

    K (N·m·s/rad) and Lambda may also be given as diagonals (sequences) from Python;
    the scenario schema (``scenario.ControllerConfig``, which extends this class)
    takes scalars.  Annotations are real types (no postponed evaluation in this
    module) because Drake's ``yaml_load_typed`` reads them.
    """

    K: float = 50.0
    Lambda: float = 5.0
    k: float = 3.0  # 1/s, decay of s_d
    epsilon: float = 1.0e-6
    delta: float = 1.0e-6
    alpha_hold: float = 0.0  # 1/s, α after tf
    switching: str = "tanh"  # sign | tanh | sat
    phi: float = 0.01  # m/s, boundary-layer width
    sigma_policy: str = "keep"  # keep | reset σ at a new segment
    k_hold: float = 50.0  # 1/s, decay of s_d after tf
    pinv_damping: float = 0.0  # m/rad: λ of the damped pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹; 0 = exact
    # Redundant arms (more joints than 3): J⁺ leaves the self-motion free.  A null-space term
    # τ_ns = −D (I − J⁺J)(q̇ + r (q − q_start)) damps it toward the start posture; D = 0 (the
    # default) leaves the paper's law exact.  It reads kinematics only (model-free).
    null_space_damping: float = 0.0  # N·m·s/rad: D
    null_space_rate: float = 2.0  # 1/s: r, how fast the posture error is pulled back
    # Issue 19: which error the surface drives to zero (``systems.task``): ``position`` (the
    # paper's), ``pose`` (position and orientation, ≥ 6 joints) or ``top_down`` (position, approach
    # axis down, yaw matched to the object's modulo 180°, ≥ 5 joints); and how a radian of
    # orientation error weighs against a metre of position error.
    task: str = "position"  # position | pose | top_down
    rot_scale: float = 0.1  # m per rad
