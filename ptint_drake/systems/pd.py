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
"""


import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.baseline_common import (
    DeclareControllerOutputs,
    layout_size,
    make_layout,
    segment_index,
)
from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.config.controller import PDConfig
from ptint_drake.systems.kinematics import FrameKinematics
from ptint_drake.systems.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.signals import TARGET, TARGET_PORT_SIZE

def pd_layout(nv: int) -> dict:
    """name -> slice of the PD controller's ``telemetry``."""
    return make_layout([("x", 3), ("xdot", 3), ("e", 3), ("edot", 3), ("integral", 3),
                        ("gains", 3), ("force", 3), ("tau", nv)])


class PDController(LeafSystem):
    """Inputs ``state`` (nq + nv), ``target`` ([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs
    ``u`` (nu), ``tau`` (nv), ``telemetry`` (``layout``).  State: ∫e (continuous, 3),
    [segment, Kp, Kd, Ki] (discrete)."""

    def __init__(self, *, plant, frame, schedule: Schedule, config: PDConfig):
        super().__init__()
        config.validate()
        self._config = config
        self._schedule = schedule
        self._nq, self._nv = plant.num_positions(), plant.num_velocities()
        self._kinematics = FrameKinematics(plant, frame)
        self.layout = pd_layout(self._nv)
        self._state_in = self.DeclareVectorInputPort("state", self._nq + self._nv)
        self._target_in = self.DeclareVectorInputPort("target", TARGET_PORT_SIZE)
        self._integral_index = self.DeclareContinuousState(3)
        self._gains_index = self.DeclareDiscreteState(np.array([-1.0, 0.0, 0.0, 0.0]))
        DeclareSegmentStartEvents(self, schedule, self._on_segment_start)
        deps = {self.time_ticket(), self.xc_ticket(), self.xd_ticket(),
                self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, "pd", layout_size(self.layout), self._calc, deps)
        DeclareControllerOutputs(self, plant, self.layout, self._eval, deps)

    def gains_for(self, tf: float) -> dict:
        """The gains this controller uses on a segment of duration tf (s)."""
        return self._config.gains_for(tf)

    def _on_segment_start(self, context, state) -> None:
        i = segment_index(self._schedule, context.get_time())
        g = self.gains_for(self._schedule[i].tf)
        state.get_mutable_discrete_state(self._gains_index).SetFromVector(
            [i, g["Kp"], g["Kd"], g["Ki"]])
        if self._config.integral_policy == "reset":
            state.get_mutable_continuous_state().get_mutable_vector().SetZero()

    def _calc(self, context) -> np.ndarray:
        qv = self._state_in.Eval(context)
        target = self._target_in.Eval(context)
        x, xdot, J = self._kinematics.compute(qv[: self._nq], qv[self._nq:])
        e, edot = x - target[TARGET.x], xdot - target[TARGET.xdot]
        integral = context.get_continuous_state_vector().CopyToVector()
        _, Kp, Kd, Ki = context.get_discrete_state(self._gains_index).value()
        force = -(Kp * e + Kd * edot + Ki * integral)
        return np.concatenate([x, xdot, e, edot, integral, [Kp, Kd, Ki], force, J.T @ force])

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[self.layout["e"]])
