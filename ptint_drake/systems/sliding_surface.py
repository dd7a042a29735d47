"""Sliding surface with a prescribed-time gain (SPEC section 2.3, paper eqs. 11-17).

    e   = x − x_r,  ė = ẋ − ẋ_r                         (11)  (``systems.task``: or the pose error)
    s   = ė + α(t) e                                      (16)
    s_d = s(t0) exp(−k (t − t0))          t < t0 + tf,   s(t0) captured at the segment start
    s_d = s_d(t0 + tf) exp(−k_hold (t − t0 − tf))   after tf (hold)
    s_x = s − s_d + Λ σ,   σ̇ = switch(s − s_d)            (17)

``switch`` is the paper's ``sign`` or a boundary layer of width φ (m/s):
``tanh`` → tanh(w/φ), ``sat`` → clip(w/φ, −1, 1).  The boundary layer is the
default because an error-controlled integrator crawls through a discontinuous
right-hand side (SPEC section 7); ``tests/test_switching.py`` measures how
closely it reproduces ``sign``.

Segment switches are Drake events: a timed (periodic, one-shot) unrestricted
update at every segment start, plus one at initialization, stores s(t0) and
the segment index.  At the instant of a switch, before its event is handled,
s_d is taken as the current s, which is exactly the value the event stores, so
every output is continuous from the right.  σ is kept across segments by
default (``sigma_policy="keep"``): it holds the integral of the switching term,
i.e. the learned gravity load, so the torque does not jump; ``"reset"`` sets it
to 0 at each new segment.

The hold after tf is a choice the paper leaves open.  Its α is 0 there, so the
surface only matches velocities: s → s_d means ė → s_d and the position drifts
by ∫ s_d dt.  With the paper's s_d that drift is |s(t0)| e^(−k tf) / k, which is
4.4 mm for the first assembly segment (tf = 0.5 s, k = 3, object at 0.1 m/s).
The hold therefore lets s_d decay at its own rate ``k_hold`` (default 50 s⁻¹,
drift ≤ s_d(tf)/k_hold); s_d stays continuous, and ``k_hold = k`` is exactly the
paper's formula.  ``alpha_hold`` (TBG) adds position feedback in the hold.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.systems.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.signals import CAPTURED, SEGMENT, TARGET_ROTATION_SIZE, surface_slots
from ptint_drake.systems.task import TASK_DIM, task_error

SWITCHING_LAWS = ("sign", "tanh", "sat")
SIGMA_POLICIES = ("keep", "reset")


def _sign(w: float) -> float:
    """The sign of one float (0 stays 0, NaN stays NaN)."""
    return 1.0 if w > 0.0 else (-1.0 if w < 0.0 else w)


def switching_law(law: str, phi: float):
    """σ̇ = switch(w) of a vector w (a list of plain floats → a list): the paper's ``sign``,
    ``tanh(w/φ)`` or ``sat(w/φ)`` = clip(w/φ, −1, 1).  Raises ValueError for another law."""
    if law == "sign":
        return lambda w: [_sign(a) for a in w]
    if law == "tanh":
        # numpy's tanh, not math.tanh: they differ in the last bit for about a quarter of
        # the arguments, and the run (step sizes, sampled peaks) should not move with it
        tanh = np.tanh
        return lambda w: [float(tanh(a / phi)) for a in w]
    if law == "sat":
        return lambda w: [min(max(a / phi, -1.0), 1.0) if a == a else a for a in w]
    raise ValueError(f"controller.switching: unknown law {law!r}, use one of {SWITCHING_LAWS}")


class SurfaceLaw:
    """The surface equations above (paper eqs. 16, 17) in plain floats, on a task error of
    dimension ``dim`` (3: position; 6: position and orientation, ``systems.task``): the one
    implementation that ``SlidingSurface`` and the fused ``PrescribedTimeInterceptor`` call."""

    def __init__(self, Lambda=5.0, k: float = 3.0, switching: str = "tanh", phi: float = 0.01,
                 sigma_policy: str = "keep", k_hold: float = 50.0, dim: int = 3):
        self._switch = switching_law(switching, float(phi))  # validates the law
        if sigma_policy not in SIGMA_POLICIES:
            raise ValueError(f"controller.sigma_policy: use one of {SIGMA_POLICIES}, got {sigma_policy!r}")
        if switching != "sign" and not phi > 0.0:
            raise ValueError(f"controller.phi: must be > 0, got {phi}")
        self.dim = int(dim)
        self.Lambda = np.broadcast_to(np.asarray(Lambda, dtype=float), (self.dim,)).copy()
        self.k = float(k)
        self.k_hold = float(k_hold)
        self.law = switching
        self.phi = float(phi)
        self.reset_sigma = sigma_policy == "reset"
        self._Lambda = tuple(self.Lambda.tolist())

    def values(self, t: float, e: list, edot: list, alpha: float, segment, captured, sigma) -> list:
        """[s_x, e, ė, s, s_d, σ̇] (``signals.surface_slots(dim)``, 6·dim plain floats) from the
        task error e, ė (``systems.task``) and plain-float sequences (lists).

        ``segment`` = [index, t0, tf, ...] of the active segment (TBG output),
        ``captured`` = [index, s(t0)] (the discrete state), ``sigma`` = σ.
        """
        s = [d + alpha * a for a, d in zip(e, edot)]
        index = segment[SEGMENT.index]
        if index < 0 or captured[CAPTURED.index] != index:
            s_d = s  # at the switch instant s(t0) is s itself
        else:
            tau, tf = t - segment[SEGMENT.t0], segment[SEGMENT.tf]
            # numpy's exp, not math.exp: they differ in the last bit, and the run would move
            if tau < tf:
                f = float(np.exp(-self.k * tau))
            else:
                f = float(np.exp(-self.k * tf - self.k_hold * (tau - tf)))
            s_d = [c * f for c in captured[1:]]
        w = [a - d for a, d in zip(s, s_d)]
        return ([a + L * g for a, L, g in zip(w, self._Lambda, sigma)]
                + e + edot + s + list(s_d) + self._switch(w))


def DeclareSegmentCapture(system, schedule: Schedule, law: SurfaceLaw, segment_and_s):
    """Declare on ``system`` the continuous state σ (``law.dim``), the discrete state [index, s(t0)]
    and the events that store s(t0) at initialization and at every later segment start.

    ``segment_and_s(context)`` returns (active segment vector, current s).
    Returns the (ContinuousStateIndex, DiscreteStateIndex) of σ and [index, s(t0)].
    """
    sigma_index = system.DeclareContinuousState(law.dim)
    capture_index = system.DeclareDiscreteState(np.array([-1.0] + [0.0] * law.dim))

    def capture(context, state):
        segment, s = segment_and_s(context)
        if segment[SEGMENT.index] < 0:
            return
        state.get_mutable_discrete_state().get_mutable_vector().SetFromVector(
            np.concatenate([[segment[SEGMENT.index]], s]))
        if law.reset_sigma:
            state.get_mutable_continuous_state().get_mutable_vector().SetZero()

    DeclareSegmentStartEvents(system, schedule, capture)
    return sigma_index, capture_index


class SlidingSurface(LeafSystem):
    """Inputs ``x``, ``xdot`` (robot point), ``x_r``, ``xdot_r`` (target), ``alpha`` (from the
    TBG) and ``segment`` ([index, t0, ...] from the TBG); with an orientation ``task``
    (``pose``, ``top_down``: ``systems.task``) also ``R`` (the tool's orientation, row-major),
    ``omega`` (its angular velocity) and ``target_rotation`` ([R_r, ω_r, ω̇_r], 15).

    Outputs ``s_x`` (what the controller uses), and for inspection ``e``, ``edot``,
    ``s``, ``s_d`` and ``sigma``, each of the task's dimension n (3 or 6).  Continuous
    state σ (n); discrete state [captured segment index, s(t0)] (1 + n).
    """

    def __init__(self, schedule: Schedule, Lambda=5.0, k: float = 3.0,
                 switching: str = "tanh", phi: float = 0.01, sigma_policy: str = "keep",
                 k_hold: float = 50.0, task: str = "position", rot_scale: float = 0.1):
        super().__init__()
        n = TASK_DIM[task]
        self._task, self._rot_scale = task, float(rot_scale)
        self._law = SurfaceLaw(Lambda, k, switching, phi, sigma_policy, k_hold, n)
        self._slots = slots = surface_slots(n)
        self._x_in = self.DeclareVectorInputPort("x", 3)
        self._xdot_in = self.DeclareVectorInputPort("xdot", 3)
        self._x_r_in = self.DeclareVectorInputPort("x_r", 3)
        self._xdot_r_in = self.DeclareVectorInputPort("xdot_r", 3)
        self._alpha_in = self.DeclareVectorInputPort("alpha", 1)
        self._segment_in = self.DeclareVectorInputPort("segment", 5)
        self._rotation_in = None
        if task != "position":
            self._rotation_in = (self.DeclareVectorInputPort("R", 9), self.DeclareVectorInputPort("omega", 3),
                                 self.DeclareVectorInputPort("target_rotation", TARGET_ROTATION_SIZE))
        DeclareSegmentCapture(self, schedule, self._law,
                              lambda c: (self._segment_in.Eval(c), self._eval(c)[slots.s]))

        deps = {self.time_ticket(), self.xc_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, "surface", slots.size, self._calc, deps)
        for name in ("s_x", "e", "edot", "s", "s_d"):
            self.DeclareVectorOutputPort(
                name, n, lambda c, o, part=getattr(slots, name): o.SetFromVector(self._eval(c)[part]),
                prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(
            "sigma", n, lambda c, o: o.SetFromVector(c.get_continuous_state_vector().CopyToVector()),
            prerequisites_of_calc={self.xc_ticket()})

    def _calc(self, context) -> np.ndarray:
        rotation = {} if self._rotation_in is None else dict(zip(
            ("R", "omega", "rot_r"), (p.Eval(context).tolist() for p in self._rotation_in)))
        e, edot = task_error(self._task, self._rot_scale, self._x_in.Eval(context).tolist(),
                             self._xdot_in.Eval(context).tolist(), self._x_r_in.Eval(context).tolist(),
                             self._xdot_r_in.Eval(context).tolist(), **rotation)
        return np.array(self._law.values(
            context.get_time(), e, edot, float(self._alpha_in.Eval(context)[0]),
            self._segment_in.Eval(context).tolist(),
            context.get_discrete_state_vector().value().tolist(),
            context.get_continuous_state_vector().CopyToVector().tolist()))

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[self._slots.sigma_dot])

    def get_s_x_output_port(self):
        return self.GetOutputPort("s_x")
