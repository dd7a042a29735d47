"""Sliding surface with a prescribed-time gain (SPEC section 2.3, paper eqs. 11-17).

    e   = x − x_r,  ė = ẋ − ẋ_r                         (11)
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
from ptint_drake.systems.signals import CAPTURED, SEGMENT, SURFACE

SWITCHING_LAWS = ("sign", "tanh", "sat")
SIGMA_POLICIES = ("keep", "reset")


def _sign(w: float) -> float:
    """The sign of one float (0 stays 0, NaN stays NaN)."""
    return 1.0 if w > 0.0 else (-1.0 if w < 0.0 else w)


def switching_law(law: str, phi: float):
    """σ̇ = switch(w) of a 3-vector w (a list of plain floats → a list): the paper's ``sign``,
    ``tanh(w/φ)`` or ``sat(w/φ)`` = clip(w/φ, −1, 1).  Raises ValueError for another law."""
    if law == "sign":
        return lambda w: [_sign(a) for a in w]
    if law == "tanh":
        # numpy's tanh, not math.tanh: they differ in the last bit for about a quarter of
        # the arguments, and the run (step sizes, sampled peaks) should not move with it
        tanh = np.tanh
        return lambda w: [float(tanh(w[0] / phi)), float(tanh(w[1] / phi)), float(tanh(w[2] / phi))]
    if law == "sat":
        return lambda w: [min(max(a / phi, -1.0), 1.0) if a == a else a for a in w]
    raise ValueError(f"controller.switching: unknown law {law!r}, use one of {SWITCHING_LAWS}")


class SurfaceLaw:
    """The surface equations above (paper eqs. 11, 16, 17) in plain floats: the one
    implementation that ``SlidingSurface`` and the fused ``PrescribedTimeInterceptor`` call."""

    def __init__(self, Lambda=5.0, k: float = 3.0, switching: str = "tanh", phi: float = 0.01,
                 sigma_policy: str = "keep", k_hold: float = 50.0):
        self._switch = switching_law(switching, float(phi))  # validates the law
        if sigma_policy not in SIGMA_POLICIES:
            raise ValueError(f"controller.sigma_policy: use one of {SIGMA_POLICIES}, got {sigma_policy!r}")
        if switching != "sign" and not phi > 0.0:
            raise ValueError(f"controller.phi: must be > 0, got {phi}")
        self.Lambda = np.broadcast_to(np.asarray(Lambda, dtype=float), (3,)).copy()
        self.k = float(k)
        self.k_hold = float(k_hold)
        self.law = switching
        self.phi = float(phi)
        self.reset_sigma = sigma_policy == "reset"
        self._Lambda = tuple(self.Lambda.tolist())

    def values(self, t: float, x, xdot, x_r, xdot_r, alpha: float, segment, captured, sigma) -> list:
        """[s_x, e, ė, s, s_d, σ̇] (``signals.SURFACE``, 18 plain floats) from plain-float
        sequences (lists).

        ``segment`` = [index, t0, tf, ...] of the active segment (TBG output),
        ``captured`` = [index, s(t0)] (the discrete state), ``sigma`` = σ.
        """
        x0, x1, x2 = x
        r0, r1, r2 = x_r
        e = [x0 - r0, x1 - r1, x2 - r2]
        x0, x1, x2 = xdot
        r0, r1, r2 = xdot_r
        edot = [x0 - r0, x1 - r1, x2 - r2]
        s0, s1, s2 = edot[0] + alpha * e[0], edot[1] + alpha * e[1], edot[2] + alpha * e[2]
        index = segment[SEGMENT.index]
        if index < 0 or captured[CAPTURED.index] != index:
            d0, d1, d2 = s0, s1, s2  # at the switch instant s(t0) is s itself
        else:
            tau, tf = t - segment[SEGMENT.t0], segment[SEGMENT.tf]
            # numpy's exp, not math.exp: they differ in the last bit, and the run would move
            if tau < tf:
                f = float(np.exp(-self.k * tau))
            else:
                f = float(np.exp(-self.k * tf - self.k_hold * (tau - tf)))
            d0, d1, d2 = (c * f for c in captured[CAPTURED.s0])
        w = [s0 - d0, s1 - d1, s2 - d2]
        L0, L1, L2 = self._Lambda
        return ([w[0] + L0 * sigma[0], w[1] + L1 * sigma[1], w[2] + L2 * sigma[2]]
                + e + edot + [s0, s1, s2, d0, d1, d2] + self._switch(w))


def DeclareSegmentCapture(system, schedule: Schedule, law: SurfaceLaw, segment_and_s):
    """Declare on ``system`` the continuous state σ (3), the discrete state [index, s(t0)]
    and the events that store s(t0) at initialization and at every later segment start.

    ``segment_and_s(context)`` returns (active segment vector, current s).
    Returns the (ContinuousStateIndex, DiscreteStateIndex) of σ and [index, s(t0)].
    """
    sigma_index = system.DeclareContinuousState(3)
    capture_index = system.DeclareDiscreteState(np.array([-1.0, 0.0, 0.0, 0.0]))

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
    TBG) and ``segment`` ([index, t0, ...] from the TBG).

    Outputs ``s_x`` (what the controller uses), and for inspection ``e``, ``edot``,
    ``s``, ``s_d`` and ``sigma``.  Continuous state σ (3); discrete state
    [captured segment index, s(t0)] (4).
    """

    def __init__(self, schedule: Schedule, Lambda=5.0, k: float = 3.0,
                 switching: str = "tanh", phi: float = 0.01, sigma_policy: str = "keep",
                 k_hold: float = 50.0):
        super().__init__()
        self._law = SurfaceLaw(Lambda, k, switching, phi, sigma_policy, k_hold)
        self._x_in = self.DeclareVectorInputPort("x", 3)
        self._xdot_in = self.DeclareVectorInputPort("xdot", 3)
        self._x_r_in = self.DeclareVectorInputPort("x_r", 3)
        self._xdot_r_in = self.DeclareVectorInputPort("xdot_r", 3)
        self._alpha_in = self.DeclareVectorInputPort("alpha", 1)
        self._segment_in = self.DeclareVectorInputPort("segment", 5)
        DeclareSegmentCapture(self, schedule, self._law,
                              lambda c: (self._segment_in.Eval(c), self._eval(c)[SURFACE.s]))

        deps = {self.time_ticket(), self.xc_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, "surface", SURFACE.size, self._calc, deps)
        for name in ("s_x", "e", "edot", "s", "s_d"):
            self.DeclareVectorOutputPort(
                name, 3, lambda c, o, part=getattr(SURFACE, name): o.SetFromVector(self._eval(c)[part]),
                prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(
            "sigma", 3, lambda c, o: o.SetFromVector(c.get_continuous_state_vector().CopyToVector()),
            prerequisites_of_calc={self.xc_ticket()})

    def _calc(self, context) -> np.ndarray:
        return np.array(self._law.values(
            context.get_time(), self._x_in.Eval(context).tolist(),
            self._xdot_in.Eval(context).tolist(), self._x_r_in.Eval(context).tolist(),
            self._xdot_r_in.Eval(context).tolist(), float(self._alpha_in.Eval(context)[0]),
            self._segment_in.Eval(context).tolist(),
            context.get_discrete_state_vector().value().tolist(),
            context.get_continuous_state_vector().CopyToVector().tolist()))

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[SURFACE.sigma_dot])

    def get_s_x_output_port(self):
        return self.GetOutputPort("s_x")
