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
from llvmlite import binding, ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import get_cython_function_address, intrinsic
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.schedule import gamma_gain  # noqa: F401  (γ of eq. 8, named here too)
from ptint_drake.systems.task.signals import TBG, TBG_PROFILE

if TYPE_CHECKING:
    from ptint_drake.systems.task.schedule import Schedule

# scipy's Boost inverse incomplete beta function (the one behind ``scipy.special.betaincinv``),
# called from compiled code through its Cython binding: registered under a name, so the compiled
# functions refer to it by name and numba can cache them (a ctypes pointer would be baked in).
_BETAINCINV = "ptint_drake_betaincinv"
binding.add_symbol(_BETAINCINV, get_cython_function_address(
    "scipy.special.cython_special", "__pyx_fuse_0betaincinv"))  # the double version


@intrinsic
def _betaincinv(typingctx, a, b, y):
    """I⁻¹(a, b; y), scipy's double-precision ``betaincinv`` (for compiled code)."""
    def codegen(context, builder, signature, args):
        double = ir.DoubleType()
        fn = cgutils.get_or_insert_function(
            builder.module, ir.FunctionType(double, [double] * 3 + [ir.IntType(32)]), _BETAINCINV)
        return builder.call(fn, [*args, ir.Constant(ir.IntType(32), 0)])
    return types.float64(types.float64, types.float64, types.float64), codegen


@njit(cache=True)
def tbg_derivatives(tau: float, tf: float, beta: float, gamma: float) -> tuple:
    """(ξ, ξ̇, ξ̈, ξ⃛) at one time τ = t − t0 since the segment start (paper eqs. 6-10);
    ``gamma`` = ``gamma_gain(tf, beta)``, computed once per segment.

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
        eta = _betaincinv(a, a, u)
        xi = 1.0 - eta
    else:
        xi = _betaincinv(a, a, 1.0 - u)
        eta = 1.0 - xi
    g = gamma
    p = xi * eta  # ξ(1−ξ)
    one_m_2xi = 1.0 - 2.0 * xi
    xi_d = -g * p**beta
    xi_dd = g * g * beta * one_m_2xi * p ** (2.0 * beta - 1.0)
    xi_ddd = -g**3 * beta * p ** (3.0 * beta - 2.0) * ((2.0 * beta - 1.0) * one_m_2xi**2 - 2.0 * p)
    return xi, xi_d, xi_dd, xi_ddd


@njit(cache=True)
def _profile(tau, tf, beta, gamma):
    out = np.empty((4, tau.size))
    for k, t in enumerate(tau.ravel()):
        out[0, k], out[1, k], out[2, k], out[3, k] = tbg_derivatives(t, tf, beta, gamma)
    return out


def tbg_profile(tau, tf: float, beta: float) -> tuple:
    """``tbg_derivatives`` at times τ (a scalar or an array): a tuple of four floats, or of
    four arrays of the shape of ``tau``."""
    g = gamma_gain(tf, beta)
    if np.ndim(tau) == 0:
        return tbg_derivatives(float(tau), float(tf), float(beta), g)
    tau_arr = np.asarray(tau, dtype=float)
    rows = _profile(np.ascontiguousarray(tau_arr), float(tf), float(beta), g)
    return tuple(rows[k].reshape(tau_arr.shape) for k in range(4))


@njit(cache=True, inline="always")
def alpha_gain(xi, xi_dot, epsilon=1e-6, delta=1e-6):
    """α = −(1 + ϵ) ξ̇ / (ξ + δ)  (paper eq. 13), ≥ 0 during the segment (floats or arrays)."""
    return -(1.0 + epsilon) * xi_dot / (xi + delta)


def alpha_peak(tf: float, beta: float, epsilon: float = 1e-6, delta: float = 1e-6) -> float:
    """Peak of α over a segment, found on a log-spaced grid just before tf."""
    tau = tf * (1.0 - np.logspace(-14, 0, 4000))
    xi, xi_d, _, _ = tbg_profile(tau, tf, beta)
    return float(np.max(alpha_gain(xi, xi_d, epsilon, delta)))


@njit(cache=True, inline="always")
def tbg_row(t: float, segments: np.ndarray, epsilon: float, delta: float, alpha_hold: float,
            out: np.ndarray) -> None:
    """``out`` ← [ξ, ξ̇, ξ̈, ξ⃛, α, index, t0, tf, β, phase] (``signals.TBG``) of the segment
    active at absolute time t; ``segments`` (4 × count): rows start, tf, β, γ (``Schedule.table``).

    phase: 0 before the first segment, 1 while converging (eqs. 6-10, α eq. 13), 2 while
    holding after tf (α = ``alpha_hold`` there)."""
    i = np.searchsorted(segments[0], t, side="right") - 1
    if i < 0:
        out[:] = 0.0
        out[0], out[5] = 1.0, -1.0
        return
    start, tf, beta = segments[0, i], segments[1, i], segments[2, i]
    tau = t - start
    out[5], out[6], out[7], out[8] = i, start, tf, beta
    if tau < tf:
        xi, xi_d, xi_dd, xi_ddd = tbg_derivatives(tau, tf, beta, segments[3, i])
        out[0], out[1], out[2], out[3] = xi, xi_d, xi_dd, xi_ddd
        out[4], out[9] = alpha_gain(xi, xi_d, epsilon, delta), 1.0
    else:
        out[0:4] = 0.0
        out[4], out[9] = alpha_hold, 2.0


def tbg_state(schedule: Schedule, t: float, epsilon: float = 1e-6, delta: float = 1e-6,
              alpha_hold: float = 0.0) -> np.ndarray:
    """[ξ, ξ̇, ξ̈, ξ⃛, α, index, t0, tf, β, phase] (``signals.TBG``) of the segment active at
    absolute time t (``tbg_row``)."""
    out = np.empty(TBG.size)
    tbg_row(float(t), schedule.table, float(epsilon), float(delta), float(alpha_hold), out)
    return out


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
        return tbg_state(self._schedule, t, self._epsilon, self._delta, self._alpha_hold)

    def get_xi_output_port(self):
        return self._xi_out

    def get_alpha_output_port(self):
        return self._alpha_out

    def get_segment_output_port(self):
        return self._segment_out
