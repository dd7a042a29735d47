"""Sliding surface with a prescribed-time gain (SPEC section 2.3, paper eqs. 11-17).

    e   = x − x_r,  ė = ẋ − ẋ_r                         (11)  (``systems.task.error``: or the pose error)
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
from numba import njit
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.error import TASK_DIM, task_error
from ptint_drake.systems.task.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.task.signals import SEGMENT, TARGET_ROTATION_SIZE, surface_slots

SWITCHING_LAWS = ("sign", "tanh", "sat")  # their codes in compiled code: the index
SIGMA_POLICIES = ("keep", "reset")


@njit(cache=True, inline="always")
def switch(law: int, phi: float, w: np.ndarray, out: np.ndarray) -> None:
    """``out`` ← switch(w) of eq. 17 elementwise: ``law`` 0 the paper's sign, 1 tanh(w/φ),
    2 sat(w/φ) = clip(w/φ, −1, 1) (codes: the index in ``SWITCHING_LAWS``; NaN stays NaN)."""
    for i in range(len(w)):
        a = w[i]
        if law == 0:
            out[i] = 1.0 if a > 0.0 else (-1.0 if a < 0.0 else a)
        elif law == 1:
            out[i] = np.tanh(a / phi)
        else:
            out[i] = min(max(a / phi, -1.0), 1.0) if a == a else a


def switching_law(law: str, phi: float):
    """σ̇ = switch(w) of a vector w (a sequence → an array): ``switch`` with the paper's
    ``sign``, ``tanh(w/φ)`` or ``sat(w/φ)``.  Raises ValueError for another law."""
    if law not in SWITCHING_LAWS:
        raise ValueError(f"controller.switching: unknown law {law!r}, use one of {SWITCHING_LAWS}")
    code, phi = SWITCHING_LAWS.index(law), float(phi)

    def apply(w) -> np.ndarray:
        w = np.asarray(w, dtype=float)
        out = np.empty_like(w)
        switch(code, phi, w, out)
        return out
    return apply


@njit(cache=True, inline="always")
def surface_law(t: float, e, edot, alpha: float, segment, captured, sigma, Lambda, k: float,
                k_hold: float, law: int, phi: float, out) -> None:
    """``out`` ← [s_x, e, ė, s, s_d, σ̇] (``signals.surface_slots(n)``) of paper eqs. 16, 17 for
    a task error e, ė of dimension n: s = ė + α e; s_d = s(t0) e^(−k τ) while τ = t − t0 < tf,
    s(t0) e^(−k tf − k_hold (τ − tf)) in the hold (s_d = s at the switch instant, before the
    capture: ``captured`` [index, s(t0)] holds another segment); s_x = s − s_d + Λ σ;
    σ̇ = switch(s − s_d) (``switch``, ``law``, φ).  ``segment`` = [index, t0, tf, …]."""
    n = len(e)
    index = segment[0]
    hold = index < 0 or captured[0] != index
    f = 0.0
    if not hold:
        tau, tf = t - segment[1], segment[2]
        f = np.exp(-k * tau) if tau < tf else np.exp(-k * tf - k_hold * (tau - tf))
    w = out[5 * n:6 * n]  # s − s_d, until σ̇ replaces it
    for i in range(n):
        s = edot[i] + alpha * e[i]
        s_d = s if hold else captured[1 + i] * f
        out[n + i], out[2 * n + i], out[3 * n + i], out[4 * n + i] = e[i], edot[i], s, s_d
        w[i] = s - s_d
        out[i] = w[i] + Lambda[i] * sigma[i]
    switch(law, phi, w, w)


class SurfaceLaw:
    """The surface equations (paper eqs. 16, 17, ``surface_law``) with their gains, on a task
    error of dimension ``dim`` (3: position; 6: position and orientation, ``systems.task.error``)."""

    def __init__(self, Lambda=5.0, k: float = 3.0, switching: str = "tanh", phi: float = 0.01,
                 sigma_policy: str = "keep", k_hold: float = 50.0, dim: int = 3):
        switching_law(switching, float(phi))  # validates the law
        if sigma_policy not in SIGMA_POLICIES:
            raise ValueError(f"controller.sigma_policy: use one of {SIGMA_POLICIES}, got {sigma_policy!r}")
        if switching != "sign" and not phi > 0.0:
            raise ValueError(f"controller.phi: must be > 0, got {phi}")
        self.dim = int(dim)
        self.Lambda = np.broadcast_to(np.asarray(Lambda, dtype=float), (self.dim,)).copy()
        self.k = float(k)
        self.k_hold = float(k_hold)
        self.law = switching
        self.code = SWITCHING_LAWS.index(switching)
        self.phi = float(phi)
        self.reset_sigma = sigma_policy == "reset"

    def values(self, t: float, e, edot, alpha: float, segment, captured, sigma) -> np.ndarray:
        """[s_x, e, ė, s, s_d, σ̇] (``signals.surface_slots(dim)``, 6·dim) from the task error
        e, ė (``systems.task.error``), α, ``segment`` = [index, t0, tf, ...] of the active segment (TBG
        output), ``captured`` = [index, s(t0)] (the discrete state) and ``sigma`` = σ."""
        out = np.empty(6 * self.dim)
        f64 = np.asarray
        surface_law(float(t), f64(e, float), f64(edot, float), float(alpha), f64(segment, float),
                    f64(captured, float), f64(sigma, float), self.Lambda, self.k, self.k_hold,
                    self.code, self.phi, out)
        return out


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
    (``pose``, ``top_down``: ``systems.task.error``) also ``R`` (the tool's orientation, row-major),
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
        return self._law.values(
            context.get_time(), e, edot, float(self._alpha_in.Eval(context)[0]),
            self._segment_in.Eval(context), context.get_discrete_state_vector().value(),
            context.get_continuous_state_vector().CopyToVector())

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[self._slots.sigma_dot])

    def get_s_x_output_port(self):
        return self.GetOutputPort("s_x")
