"""Time base generator (TBG), SPEC section 2.1 (paper eqs. 6-10).

    ξ̇ = −γ (ξ(1−ξ))^β,  ξ(t0) = 1,  γ = B(1−β, 1−β) / tf

has the exact solution ξ(t) = I⁻¹(1−β, 1−β; 1 − τ/tf), τ = t − t0, where I⁻¹
is the inverse regularized incomplete beta function.  ξ reaches 0 exactly at
τ = tf and stays 0 afterwards.  Near ξ ≈ 1 the complement η = 1 − ξ is
computed directly (η = I⁻¹(1−β, 1−β; τ/tf)) because for β ≳ 0.6 it falls below
double precision next to 1.0; every derivative is written in terms of the
product ξη so that no precision is lost at either end.

The same closed form gives the prescribed-time gain of SPEC section 2.2,

    α(t) = −α0 ξ̇ / (ξ + δ),  α0 = 1 + ϵ,

and, after tf, the hold gain ``alpha_hold`` (0 in the paper).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from pydrake.systems.framework import LeafSystem
from scipy.special import beta as beta_function
# scipy's Boost inverse through its Cython binding: bit-identical to the ``betaincinv`` ufunc,
# without the ufunc's per-call dispatch (about 0.9 µs instead of 1.7 µs for one scalar).
from scipy.special.cython_special import betaincinv

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.systems.signals import TBG, TBG_PROFILE

if TYPE_CHECKING:
    from ptint_drake.systems.schedule import Schedule


def gamma_gain(tf: float, beta: float) -> float:
    """γ = Γ(1−β)² / (tf Γ(2−2β)) = B(1−β, 1−β) / tf  (paper eq. 8)."""
    return float(beta_function(1.0 - beta, 1.0 - beta)) / tf


def tbg_derivatives(tau: float, tf: float, beta: float, gamma: float) -> tuple:
    """(ξ, ξ̇, ξ̈, ξ⃛) at one time τ = t − t0 since the segment start, in plain floats
    (paper eqs. 6-10); ``gamma`` = ``gamma_gain(tf, beta)``, computed once per segment.

    For τ ≤ 0 the TBG sits at ξ = 1 (not yet started); for τ ≥ tf it is 0.  The smaller of
    ξ and η = 1 − ξ is the inverse incomplete beta function, the other 1 − it, and every
    derivative is written with the product ξη, so neither end loses precision.
    """
    u = tau / tf
    if u <= 0.0:
        return 1.0, 0.0, 0.0, 0.0
    if u >= 1.0:
        return 0.0, 0.0, 0.0, 0.0
    a = 1.0 - beta
    if u < 0.5:
        eta = betaincinv(a, a, u)
        xi = 1.0 - eta
    else:
        xi = betaincinv(a, a, 1.0 - u)
        eta = 1.0 - xi
    g = gamma
    p = xi * eta  # ξ(1−ξ)
    one_m_2xi = 1.0 - 2.0 * xi
    xi_d = -g * p**beta
    xi_dd = g * g * beta * one_m_2xi * p ** (2.0 * beta - 1.0)
    xi_ddd = -g**3 * beta * p ** (3.0 * beta - 2.0) * ((2.0 * beta - 1.0) * one_m_2xi**2 - 2.0 * p)
    return xi, xi_d, xi_dd, xi_ddd


def tbg_profile(tau, tf: float, beta: float) -> tuple:
    """``tbg_derivatives`` at times τ (a scalar or an array): a tuple of four floats, or of
    four arrays of the shape of ``tau``."""
    g = gamma_gain(tf, beta)
    if np.ndim(tau) == 0:
        return tbg_derivatives(float(tau), tf, beta, g)
    tau_arr = np.asarray(tau, dtype=float)
    rows = np.array([tbg_derivatives(t, tf, beta, g) for t in tau_arr.ravel().tolist()])
    return tuple(rows[:, k].reshape(tau_arr.shape) for k in range(4))


def alpha_gain(xi, xi_dot, epsilon: float = 1e-6, delta: float = 1e-6):
    """α = −(1 + ϵ) ξ̇ / (ξ + δ)  (paper eq. 13), ≥ 0 during the segment (floats or arrays)."""
    return -(1.0 + epsilon) * xi_dot / (xi + delta)


def alpha_peak(tf: float, beta: float, epsilon: float = 1e-6, delta: float = 1e-6) -> float:
    """Peak of α over a segment, found on a log-spaced grid just before tf."""
    tau = tf * (1.0 - np.logspace(-14, 0, 4000))
    xi, xi_d, _, _ = tbg_profile(tau, tf, beta)
    return float(np.max(alpha_gain(xi, xi_d, epsilon, delta)))


def tbg_state(schedule: Schedule, t: float, epsilon: float = 1e-6, delta: float = 1e-6,
              alpha_hold: float = 0.0) -> list:
    """[ξ, ξ̇, ξ̈, ξ⃛, α, index, t0, tf, β, phase] (``signals.TBG``, plain floats) of the
    segment active at absolute time t.

    phase: 0 before the first segment, 1 while converging, 2 while holding after tf
    (α = ``alpha_hold`` there).
    """
    i = schedule.active(t)
    if i < 0:
        return [1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0]
    seg = schedule[i]
    tau = t - seg.start
    if tau < seg.tf:
        xi, xi_d, xi_dd, xi_ddd = tbg_derivatives(tau, seg.tf, seg.beta, schedule.gamma(i))
        return [xi, xi_d, xi_dd, xi_ddd, alpha_gain(xi, xi_d, epsilon, delta),
                float(i), float(seg.start), float(seg.tf), float(seg.beta), 1.0]
    return [0.0, 0.0, 0.0, 0.0, float(alpha_hold), float(i), float(seg.start), float(seg.tf),
            float(seg.beta), 2.0]


class TimeBaseGenerator(LeafSystem):
    """The TBG of the active segment as a Drake system (paper eqs. 6-10, 13).

    Stateless: the closed form is exact, so restarting the TBG at a new segment
    is a matter of time alone.  Output ports (all functions of time only):

    - ``xi``: [ξ, ξ̇, ξ̈, ξ⃛] of the active segment (ξ = 1 before the first start);
    - ``alpha``: [α], the prescribed-time gain, ``alpha_hold`` after tf;
    - ``segment``: [index, t0, tf, β, phase] with phase 0 before the first
      segment, 1 while converging, 2 while holding after tf.
    """

    def __init__(self, schedule: Schedule, epsilon: float = 1e-6, delta: float = 1e-6,
                 alpha_hold: float = 0.0):
        super().__init__()
        self._schedule = schedule
        self._epsilon = epsilon
        self._delta = delta
        self._alpha_hold = alpha_hold
        time_only = {self.time_ticket()}
        self._eval = DeclareVectorCache(
            self, "tbg", TBG.size, lambda c: self.evaluate(c.get_time()), time_only)
        self._xi_out = self.DeclareVectorOutputPort(
            "xi", 4, lambda c, o: o.SetFromVector(self._eval(c)[TBG_PROFILE]),
            prerequisites_of_calc=time_only)
        self._alpha_out = self.DeclareVectorOutputPort(
            "alpha", 1, lambda c, o: o.SetFromVector(self._eval(c)[TBG.alpha:TBG.alpha + 1]),
            prerequisites_of_calc=time_only)
        self._segment_out = self.DeclareVectorOutputPort(
            "segment", 5, lambda c, o: o.SetFromVector(self._eval(c)[TBG.segment]),
            prerequisites_of_calc=time_only)

    @property
    def schedule(self) -> Schedule:
        return self._schedule

    def evaluate(self, t: float) -> np.ndarray:
        """[ξ, ξ̇, ξ̈, ξ⃛, α, index, t0, tf, β, phase] at absolute time t (``tbg_state``)."""
        return np.array(tbg_state(self._schedule, t, self._epsilon, self._delta, self._alpha_hold))

    def get_xi_output_port(self):
        return self._xi_out

    def get_alpha_output_port(self):
        return self._alpha_out

    def get_segment_output_port(self):
        return self._segment_out
