"""Model-free second-order sliding-mode baseline: the paper's controller without the TBG.
# no postponed annotations here: Drake's yaml_load_typed / yaml_dump_typed read SmcOptions' types


    e   = x − x_r ,  ė = ẋ − ẋ_r                  (m, m/s)
    s   = ė + λ e ,   λ = lambda_factor / tf        (m/s; λ in 1/s, constant per segment)
    s_x = s + Λ σ ,   σ̇ = switch(s)                 (σ in m; switch = sign | tanh(·/φ) | sat(·/φ))
    τ   = −K J⁺(q) s_x                              (N·m; K in N·m·s/rad)

On the surface s = 0 the error decays as e(t0) e^(−λ(t − t0)); lambda_factor = 4 leaves
e^(−4) ≈ 2 % of e(t0) at t0 + tf ("settles in about tf") but arrives whenever λ says — no
prescribed time.  There is no s_d term: the loop does not start on the surface.  K, Λ, the
switching law, φ, pinv_damping and the σ policy are the paper controller's (defaults
K = 50, Λ = 5, tanh, φ = 0.01 m/s, σ kept across segments); ``SMCConfig.from_gains``
copies them from a ``ControllerGains``.  At every segment start (a Drake event) λ of the
new segment is stored in the discrete state and, with ``sigma_policy = "reset"``, σ is
zeroed.

Model-free: only the frame's position and Jacobian are evaluated (``FrameKinematics``),
never the mass matrix, Coriolis, gravity or inverse dynamics.

In the controller slot: ``smc``: a first-order sliding mode in the slot.

It shares the paper's gains K and Λ (flat on ``controller``) and takes its own surface slope
under ``controller.smc``: a constant λ = ``lambda_factor`` / tf per segment (no TBG).
"""

from dataclasses import dataclass

import numpy as np

from ptint_drake.config.controller import SmcOptions
from ptint_drake.controllers.baseline import TaskSpaceBaseline, layout_size, make_layout
from ptint_drake.controllers.ptsmc import gains_of
from ptint_drake.controllers.ptsmc.law import smc_torque
from ptint_drake.controllers.ptsmc.sliding_surface import SIGMA_POLICIES, switching_law
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.task.schedule import Schedule

_SHARED = ("K", "Lambda", "switching", "phi", "sigma_policy", "pinv_damping")


@dataclass
class SMCConfig:
    """First-order-surface SMC parameters (units in the module docstring)."""

    lambda_factor: float = 4.0  # λ = lambda_factor / tf (1/s)
    K: float = 50.0  # N·m·s/rad
    Lambda: float = 5.0  # 1/s, weight of σ in s_x
    switching: str = "tanh"  # sign | tanh | sat
    phi: float = 0.01  # m/s, boundary-layer width
    sigma_policy: str = "keep"  # keep | reset σ at a new segment
    pinv_damping: float = 0.0  # m/rad, damped pseudoinverse; 0 = exact

    @classmethod
    def from_gains(cls, gains, lambda_factor: float = 4.0) -> "SMCConfig":
        """The fields shared with the paper controller copied from a ``ControllerGains``."""
        return cls(lambda_factor=lambda_factor, **{k: getattr(gains, k) for k in _SHARED})

    def validate(self) -> None:
        switching_law(self.switching, self.phi)  # validates the law
        if self.switching != "sign" and not self.phi > 0.0:
            raise ValueError(f"smc.phi: must be > 0, got {self.phi}")
        if self.sigma_policy not in SIGMA_POLICIES:
            raise ValueError(f"smc.sigma_policy: use one of {SIGMA_POLICIES}, got {self.sigma_policy!r}")
        if not self.lambda_factor > 0.0:
            raise ValueError(f"smc.lambda_factor: must be > 0, got {self.lambda_factor}")


def smc_layout(nv: int) -> dict:
    """name -> slice of the SMC baseline's ``telemetry``."""
    return make_layout([("x", 3), ("xdot", 3), ("e", 3), ("edot", 3), ("lambda", 1), ("s", 3),
                        ("s_x", 3), ("sigma", 3), ("tau", nv)])


class FirstOrderSMC(TaskSpaceBaseline):
    """Inputs ``state`` (nq + nv), ``target`` ([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs
    ``u`` (nu), ``tau`` (nv), ``telemetry`` (``layout``).  State: σ (continuous, 3),
    [segment, λ] (discrete); ports, segment starts and e, ė: ``TaskSpaceBaseline``."""

    def __init__(self, *, plant, frame, schedule: Schedule, config: SMCConfig):
        config.validate()
        nv = plant.num_velocities()
        layout = smc_layout(nv)
        size = layout_size(layout)
        # the cache holds the telemetry, then σ̇ (3)
        super().__init__(plant=plant, frame=frame, schedule=schedule, layout=layout, name="smc", values=1,
                         reset=config.sigma_policy == "reset", derivative=slice(size, size + 3), extra=3)
        self._config = config
        self._K_floats = np.broadcast_to(np.asarray(config.K, dtype=float), (nv,)).tolist()
        self._Lambda = np.broadcast_to(np.asarray(config.Lambda, dtype=float), (3,)).copy()
        self._switch = switching_law(config.switching, float(config.phi))

    def lambda_for(self, tf: float) -> float:
        """λ (1/s) on a segment of duration tf (s)."""
        return self._config.lambda_factor / tf

    def _segment_values(self, tf: float) -> list:
        """[λ] of a segment of duration tf (s)."""
        return [self.lambda_for(tf)]

    def _calc(self, context) -> np.ndarray:
        r = self.read(context)
        lam = r.segment[1]
        s = r.edot + lam * r.e
        s_x = s + self._Lambda * r.memory
        tau = smc_torque(self._K_floats, r.J, s_x, self._config.pinv_damping)
        sigma_dot = self._switch(s.tolist())
        return np.concatenate([r.x, r.xdot, r.e, r.edot, [lam], s, s_x, r.memory, tau, sigma_dot])

NAME = "smc"
SUMMARY = "first-order sliding mode with a constant slope λ = lambda_factor/tf (no TBG), model-free"


CONFIG = SmcOptions


def settings_of(block) -> SMCConfig:
    """The system's configuration: the paper's gains of ``block`` and its ``smc`` options."""
    return SMCConfig.from_gains(gains_of(block), lambda_factor=block.smc.lambda_factor)


def AddSmc(slot: ControllerSlot, config: SMCConfig, target: TargetView) -> ControllerHandles:
    """Add the first-order SMC and wire it to the slot."""
    system = slot.builder.AddNamedSystem("smc", FirstOrderSMC(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config))
    port = slot.connect(system, target)
    notes = [f"smc segment {i}: λ = {config.lambda_factor:g}/tf = {config.lambda_factor / s.tf:.3g} 1/s, "
             f"K = {config.K:g}, Λ = {config.Lambda:g}" for i, s in enumerate(slot.schedule.segments)]
    return telemetry_handles(NAME, system, port, notes)
