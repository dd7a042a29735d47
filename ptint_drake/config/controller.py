"""The scenario's ``controller`` block, declared: the paper's gains (``ControllerGains``, paper
section 3.1), which controller runs (``type``), a plugin's ``params``, the drive's
``control_period``, and one block per bundled controller with settings of its own
(``controller.pd``, ``controller.smc``, ``controller.ct_quintic``).  The registry
(``controllers.REGISTRY``) names the same blocks; ``tests/unit/test_registry.py`` checks that
the two agree.  (No postponed annotations: Drake's ``yaml_load_typed`` reads the types.)
"""

from dataclasses import dataclass, field
from typing import Dict, List, Optional, Union


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
    # Issue 45, the null-space posture task: the rest posture q_rest that replaces q_start above
    # (degrees, one per joint; empty = the start posture), and a joint-limit term: within this many
    # degrees of a joint's position limit (the model's kinematic limits) the reference is pushed
    # back from the limit, ``controllers.ptsmc.law.LIMIT_WEIGHT`` times harder per radian than toward
    # q_rest (0 = off).  Both act through D, in the null space only.
    null_space_posture_deg: List[float] = field(default_factory=list)
    null_space_limit_margin_deg: float = 0.0
    # Issue 19: which error the surface drives to zero (``systems.task.error``): ``position`` (the
    # paper's), ``pose`` (position and orientation, ≥ 6 joints) or ``top_down`` (position, approach
    # axis down, yaw matched to the object's modulo 180°, ≥ 5 joints); and how a radian of
    # orientation error weighs against a metre of position error.
    task: str = "position"  # position | pose | top_down
    rot_scale: float = 0.1  # m per rad


INTEGRAL_POLICIES = ("keep", "reset")


@dataclass
class PDConfig:
    """Parameters of the PID gain rule (see the module docstring)."""

    settling_factor: float = 8.4  # c: ω = c / tf (rad/s); 8.4 → 1 % of a step left at tf
    mass: float = 10.0  # m (kg), design task-space mass of the pole placement
    Kp: float | None = None  # N/m, overrides 3 m ω² when set
    Kd: float | None = None  # N·s/m, overrides 3 m ω when set
    Ki: float | None = None  # N/(m·s), overrides m ω³ when set (0 = PD)
    integral_policy: str = "keep"  # keep | reset ∫e at a new segment

    def gains_for(self, tf: float) -> dict:
        """{"Kp", "Kd", "Ki", "omega"} used on a segment of duration tf (s)."""
        if not tf > 0.0:
            raise ValueError(f"pd: tf must be > 0, got {tf}")
        omega = self.settling_factor / tf
        m = self.mass
        rule = {"Kp": 3.0 * m * omega**2, "Kd": 3.0 * m * omega, "Ki": m * omega**3}
        gains = {k: float(rule[k] if getattr(self, k) is None else getattr(self, k)) for k in rule}
        gains["omega"] = omega
        return gains

    def validate(self) -> None:
        if self.integral_policy not in INTEGRAL_POLICIES:
            raise ValueError(f"pd.integral_policy: use one of {INTEGRAL_POLICIES}, "
                             f"got {self.integral_policy!r}")
        if not (self.settling_factor > 0.0 and self.mass > 0.0):
            raise ValueError("pd.settling_factor and pd.mass must be > 0")


@dataclass
class SmcOptions:
    """``controller.smc``: what the first-order SMC adds to the paper's gains."""

    lambda_factor: float = 4.0  # smc: constant λ = lambda_factor / tf (1/s); 4 settles in about tf

    def validate(self) -> None:
        if not self.lambda_factor > 0.0:
            raise ValueError(f"smc.lambda_factor: must be > 0, got {self.lambda_factor}")


@dataclass
class CtQuinticConfig:
    """Plan and tracking parameters (units in the module docstring)."""

    omega: float = 20.0  # rad/s: kp = ω² (1/s²), kd = 2ω (1/s) of the joint-space tracking
    ki: float = 0.0  # 1/s³, integral gain of the InverseDynamicsController
    k_x: float = 20.0  # 1/s, task-space position gain of the differential IK after tf
    ik_tolerance: float = 1.0e-6  # m, |f(q_f) − x_f|∞ allowed by the IK
    on_ik_failure: str = "nearest"  # nearest (closest reachable point) | raise (ValueError)
    pinv_damping: float = 0.01  # m/rad: J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹ in v_f and the differential IK; 0 = exact

    def validate(self) -> None:
        if not (self.omega > 0.0 and self.ik_tolerance > 0.0
                and min(self.k_x, self.ki, self.pinv_damping) >= 0.0):
            raise ValueError("ct_quintic: omega and ik_tolerance must be > 0, k_x, ki and "
                             "pinv_damping ≥ 0")
        if self.on_ik_failure not in ("nearest", "raise"):
            raise ValueError(f"ct_quintic.on_ik_failure: use nearest or raise, got {self.on_ik_failure!r}")


# Issue 33: the damping a scenario gets when it leaves ``controller.pinv_damping`` out.  A 6-joint arm
# on the 6-D ``top_down`` task has a square Jacobian: no null space to steer around its wrist
# singularity (rvm1_6dof's roll-pitch-roll wrist at pitch 0, which a place near the base cannot
# avoid), and the exact J⁺ answers a small orientation error there with large, opposite roll rates.
# Measured on rvm1_6dof (docs/pick_place.md "The 6-joint arm"): undamped, assembly_pick_place and
# the two-belt scenario of tests/two_belt_pick.yaml collide and drop parts; λ = 0.01, 0.015 and 0.02
# m/rad place every part of both (and conveyor_pick_place's), 0.006 does not (both miss), 0.03
# leaves the two-belt box 3.7 mm from its slot.  0.015 sits in the middle of that band.  Every
# other case keeps the paper's exact J⁺ (0): a 5-joint arm on top_down (6 × 5, least squares),
# the position and pose tasks.
SQUARE_TOP_DOWN_DAMPING = 0.015  # m/rad


def default_pinv_damping(task: str, n_joints: int) -> float:
    """``controller.pinv_damping`` when the scenario leaves it out: ``SQUARE_TOP_DOWN_DAMPING``
    for ``top_down`` on an arm of 6 or more joints, else 0 (the exact pseudoinverse)."""
    return SQUARE_TOP_DOWN_DAMPING if task == "top_down" and n_joints >= 6 else 0.0


ParamValue = Union[List[float], float, int, str]  # a plugin's setting (the order is Drake YAML's)


@dataclass
class ControllerConfig(ControllerGains):
    """The scenario's ``controller`` block: the paper's gains flat (``ControllerGains``, shared by
    ``smc``), which controller runs (``type``), a plugin's ``params``, and one block per bundled
    controller with settings of its own."""

    # a plain field rather than a tagged YAML variant, so that ``--set controller.type=pd``
    # works and an untagged mapping stays the paper's controller
    # None (left out): ``default_pinv_damping`` of the task and the arm's joints, set when the
    # scenario is validated (``validation.validate``); a number: that λ (m/rad, 0 = exact J⁺)
    pinv_damping: Optional[float] = None
    type: str = "ptsmc"  # a name of controllers.REGISTRY, or "module:Class"
    implementation: str = "fused"  # ptsmc: "fused" one LeafSystem, or "blocks"
    params: Dict[str, ParamValue] = field(default_factory=dict)  # a plugin's settings
    control_period: float = 0.0  # s: > 0 sampled, torque held between samples
    pd: PDConfig = field(default_factory=PDConfig)
    smc: SmcOptions = field(default_factory=SmcOptions)
    ct_quintic: CtQuinticConfig = field(default_factory=CtQuinticConfig)
