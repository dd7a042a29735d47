"""Model-free task-space PID baseline (no time base generator, no sliding surface).

    e  = x − x_r ,  ė = ẋ − ẋ_r                      x = f(q), ẋ = J(q) q̇   (m, m/s)
    τ  = −Jᵀ(q) (Kp e + Kd ė + Ki ∫e dt)             (N·m; the bracket is a force, N)

Gain rule, one per segment of duration tf (s): the closed loop of a point of design
mass m (kg) under this PID, m ë = −Kp e − Kd ė − Ki ∫e, is given a triple real pole at
−ω with ω = c / tf (rad/s):

    Kd = 3 m ω  (N·s/m),   Kp = 3 m ω²  (N/m),   Ki = m ω³  (N/(m·s))

For a step in x_r that ideal loop leaves e(t) = e0 (1 + ωt + (ωt)²/2) e^(−ωt): with the
default c = 8.4 that is 1 % of e0 at t = tf, i.e. "settles in tf".  The integral term
(all three gains come from the same pole placement) rejects a constant load such as
gravity at the same rate ω; the default m = 10 kg is a margin over the RV-M1's task-space
inertia (≈ 2–5 kg) so that gravity sags the arm by only ~2 cm before the integral takes
it.  ``Kp``, ``Kd``, ``Ki`` in the config, when set, override the rule on every segment.

At every segment start (a Drake event) the gains of the new segment are stored in the
discrete state.  ∫e (continuous state, m·s) is kept across segments by default
(``integral_policy = "keep"``: it holds the learned gravity load, so the torque only jumps
by Kp Δe); ``"reset"`` zeroes it.  No anti-windup.

Model-free: it evaluates the frame's position and Jacobian only (``FrameKinematics``),
never the mass matrix, Coriolis, gravity or inverse dynamics.

In the controller slot: ``pd``: a task-space PID in the slot.

Settings under ``controller.pd`` (``controllers.pd.PDConfig``: the pole-placement rule per segment,
or fixed Kp, Kd, Ki).
"""


import numpy as np

from ptint_drake.config.controller import PDConfig
from ptint_drake.controllers.baseline import TaskSpaceBaseline, make_layout
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.task.schedule import Schedule


def pd_layout(nv: int) -> dict:
    """name -> slice of the PD controller's ``telemetry``."""
    return make_layout([("x", 3), ("xdot", 3), ("e", 3), ("edot", 3), ("integral", 3),
                        ("gains", 3), ("force", 3), ("tau", nv)])


class PDController(TaskSpaceBaseline):
    """Inputs ``state`` (nq + nv), ``target`` ([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs
    ``u`` (nu), ``tau`` (nv), ``telemetry`` (``layout``).  State: ∫e (continuous, 3),
    [segment, Kp, Kd, Ki] (discrete); ports, segment starts and e, ė: ``TaskSpaceBaseline``."""

    def __init__(self, *, plant, frame, schedule: Schedule, config: PDConfig):
        config.validate()
        layout = pd_layout(plant.num_velocities())
        super().__init__(plant=plant, frame=frame, schedule=schedule, layout=layout, name="pd", values=3,
                         reset=config.integral_policy == "reset", derivative=layout["e"])
        self._config = config

    def gains_for(self, tf: float) -> dict:
        """The gains this controller uses on a segment of duration tf (s)."""
        return self._config.gains_for(tf)

    def _segment_values(self, tf: float) -> list:
        """[Kp, Kd, Ki] of a segment of duration tf (s)."""
        g = self.gains_for(tf)
        return [g["Kp"], g["Kd"], g["Ki"]]

    def _calc(self, context) -> np.ndarray:
        r = self.read(context)
        _, Kp, Kd, Ki = r.segment
        force = -(Kp * r.e + Kd * r.edot + Ki * r.memory)
        return np.concatenate([r.x, r.xdot, r.e, r.edot, r.memory, [Kp, Kd, Ki], force, r.J.T @ force])

NAME = "pd"
SUMMARY = "task-space PID, gains by pole placement per segment (no TBG), model-free"
CONFIG = PDConfig


def AddPd(slot: ControllerSlot, config: PDConfig, target: TargetView) -> ControllerHandles:
    """Add the PID and wire it to the slot."""
    system = slot.builder.AddNamedSystem("pd", PDController(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config))
    port = slot.connect(system, target)
    notes = []
    for i, segment in enumerate(slot.schedule.segments):
        g = config.gains_for(segment.tf)
        notes.append(f"pd segment {i}: Kp = {g['Kp']:.4g} N/m, Kd = {g['Kd']:.4g} N·s/m, "
                     f"Ki = {g['Ki']:.4g} N/(m·s) (triple pole at −{g['omega']:.3g} rad/s for "
                     f"{config.mass:g} kg)")
    return telemetry_handles(NAME, system, port, notes)
