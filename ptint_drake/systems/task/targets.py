"""Moving targets x_r(t) (SPEC section 5.2) and the Drake source that emits them.

Both kinds are functions of absolute time t:

- ``SinusoidTarget``: x_r = center + amplitude ⊙ sin(ω t + phase)
  (the paper's curve, eq. 28, is center (0.24, 0, 0.3), amplitude 0.1,
  ω = 1.5, phase (0, π/2, 0));
- ``LinearTarget``: x_r = start + velocity · t (an object on a conveyor);
- ``WaypointTarget``: a C² cubic spline through recorded samples (SPEC 5.4 ``waypoints``);
- ``BallisticTarget``: a thrown object in free flight from its release time r,
  x_r = start + velocity (t − r) + gravity (t − r)²/2 for t ≥ r (no drag); before r it is
  held at ``start`` (and a camera does not see it).

Any of them may carry an orientation (``orientation.OrientedTarget``, issue 19).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from numba import njit
from pydrake.systems.framework import LeafSystem
from pydrake.trajectories import PiecewisePolynomial

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.orientation import active_rotation_values
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET, TARGET_PORT, TARGET_PORT_SIZE, TARGET_ROTATION_SIZE

# Compiled targets: a row [kind, coefficients…] of ``COMPILED_WIDTH`` floats per target.
SINUSOID, LINEAR, BALLISTIC = 1.0, 2.0, 3.0
COMPILED_WIDTH = 38


@njit(cache=True, inline="always")
def target_row(c, t: float, out) -> None:
    """``out[:12]`` ← [x_r, ẋ_r, ẍ_r, x⃛_r] at time t of the target whose row is c (the
    ``compiled`` row of a ``SinusoidTarget``, ``LinearTarget`` or ``BallisticTarget``)."""
    kind = c[0]
    if kind == SINUSOID:  # c = [kind, offset (12), gain (12), shift (12), ω]
        wt = c[37] * t
        for k in range(12):
            out[k] = c[1 + k] + c[13 + k] * np.sin(wt + c[25 + k])
    elif kind == LINEAR:  # c = [kind, start (3), velocity (3)]
        for i in range(3):
            out[i], out[3 + i], out[6 + i], out[9 + i] = c[1 + i] + c[4 + i] * t, c[4 + i], 0.0, 0.0
    else:  # BALLISTIC: c = [kind, start (3), velocity (3), gravity (3), release]
        tau = t - c[10]
        for i in range(3):
            if tau < 0.0:
                out[i], out[3 + i], out[6 + i] = c[1 + i], 0.0, 0.0
            else:
                out[i] = c[1 + i] + c[4 + i] * tau + 0.5 * tau * tau * c[7 + i]
                out[3 + i], out[6 + i] = c[4 + i] + tau * c[7 + i], c[7 + i]
            out[9 + i] = 0.0


def _compiled_row(kind: float, *parts) -> np.ndarray:
    row = np.zeros(COMPILED_WIDTH)
    values = np.concatenate([np.ravel(p) for p in parts])
    row[0], row[1:1 + len(values)] = kind, values
    return row


def _evaluate(row: np.ndarray, t: float) -> np.ndarray:
    out = np.empty(12)
    target_row(row, float(t), out)
    return out


def compiled_targets(targets: Sequence):
    """The targets' ``compiled`` rows stacked (count × ``COMPILED_WIDTH``), or None when one of
    them has none (a waypoint or oriented target: evaluated in Python)."""
    rows = [getattr(tg, "compiled", None) for tg in targets]
    return None if any(r is None for r in rows) else np.array(rows)


@dataclass(frozen=True)
class SinusoidTarget:
    center: np.ndarray
    amplitude: np.ndarray
    omega: float
    phase: np.ndarray

    def __post_init__(self):
        for name in ("center", "amplitude", "phase"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        # the k-th derivative of a sin(ωt + φ) is a ωᵏ sin(ωt + φ + kπ/2), for k = 0..3:
        # offset, gain and shift of the 12 values (``target_row``)
        a, w = self.amplitude, self.omega
        object.__setattr__(self, "compiled", _compiled_row(
            SINUSOID, self.center, np.zeros(9), a, a * w, a * w**2, a * w**3,
            *[self.phase + k * np.pi / 2 for k in range(4)], float(w)))

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t (``target_row``)."""
        return _evaluate(self.compiled, t)


@dataclass(frozen=True)
class LinearTarget:
    start: np.ndarray
    velocity: np.ndarray

    def __post_init__(self):
        for name in ("start", "velocity"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        object.__setattr__(self, "compiled", _compiled_row(LINEAR, self.start, self.velocity))

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t (``target_row``)."""
        return _evaluate(self.compiled, t)


@dataclass(frozen=True)
class BallisticTarget:
    start: np.ndarray
    velocity: np.ndarray
    gravity: np.ndarray
    release: float = 0.0

    def __post_init__(self):
        for name in ("start", "velocity", "gravity"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        object.__setattr__(self, "compiled", _compiled_row(
            BALLISTIC, self.start, self.velocity, self.gravity, float(self.release)))

    @property
    def visible_from(self) -> float:
        """The release time: a camera sees the object from then on."""
        return float(self.release)

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t (held at ``start`` before release;
        ``target_row``)."""
        return _evaluate(self.compiled, t)


def target_values(target, t: float) -> list:
    """``target.evaluate(t)`` as a list of plain floats (its ``values`` when it has one)."""
    values = getattr(target, "values", None)
    return values(t) if values is not None else target.evaluate(t).tolist()


def active_target_values(schedule: Schedule, targets: Sequence, t: float) -> list:
    """[x_r, ẋ_r, ẍ_r, x⃛_r] (``signals.TARGET``, 12 plain floats) of the target of the segment
    active at t (the first before it)."""
    return target_values(targets[max(schedule.active(t), 0)], t)


class TargetSource(LeafSystem):
    """x_r, ẋ_r, ẍ_r of the target of the active segment (one target per segment).

    Output ports ``x_r``, ``xdot_r``, ``xddot_r`` (3 each) and ``target`` (the three
    stacked, ``signals.TARGET_PORT``) depend on time only.
    Output port ``target_rotation`` ([R_r row-major, ω_r, ω̇_r], ``signals.TARGET_ROTATION``,
    15) is the active target's orientation (an unturned, fixed frame for a target without one).
    Before the first segment starts, the first target is emitted.  Output port
    ``objects`` (3 × number of segments) gives every target's position at t,
    which a replay uses to draw the objects that are not being chased.
    """

    def __init__(self, schedule: Schedule, targets: Sequence):
        super().__init__()
        if len(targets) != len(schedule):
            raise ValueError(
                f"targets: one target per segment is needed, got {len(targets)} "
                f"for {len(schedule)} segments")
        self._schedule = schedule
        self._targets = tuple(targets)
        time_only = {self.time_ticket()}
        self._eval = DeclareVectorCache(
            self, "target", 12, lambda c: self.evaluate(c.get_time()), time_only)
        self._x_out = self.DeclareVectorOutputPort(
            "x_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[TARGET.x]),
            prerequisites_of_calc=time_only)
        self._xdot_out = self.DeclareVectorOutputPort(
            "xdot_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[TARGET.xdot]),
            prerequisites_of_calc=time_only)
        self._xddot_out = self.DeclareVectorOutputPort(
            "xddot_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[TARGET.xddot]),
            prerequisites_of_calc=time_only)
        self._target_out = self.DeclareVectorOutputPort(
            "target", TARGET_PORT_SIZE, lambda c, o: o.SetFromVector(self._eval(c)[TARGET_PORT]),
            prerequisites_of_calc=time_only)
        self.DeclareVectorOutputPort(
            "target_rotation", TARGET_ROTATION_SIZE,
            lambda c, o: o.SetFromVector(active_rotation_values(self._schedule, self._targets, c.get_time())),
            prerequisites_of_calc=time_only)
        self._objects_out = self.DeclareVectorOutputPort(
            "objects", 3 * len(targets),
            lambda c, o: o.SetFromVector(
                np.concatenate([tg.evaluate(c.get_time())[TARGET.x] for tg in self._targets])),
            prerequisites_of_calc=time_only)

    @property
    def targets(self):
        return self._targets

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] of the target active at absolute time t."""
        return np.array(active_target_values(self._schedule, self._targets, t))

    def get_x_r_output_port(self):
        return self._x_out

    def get_xdot_r_output_port(self):
        return self._xdot_out

    def get_xddot_r_output_port(self):
        return self._xddot_out

    def get_objects_output_port(self):
        return self._objects_out


class WaypointTarget:
    """A target through recorded samples: x_r(time[i]) = position[i] exactly.

    Between the first and the last sample: Drake's
    ``PiecewisePolynomial.CubicWithContinuousSecondDerivatives`` with the not-a-knot end
    condition (C² everywhere; it reproduces any cubic, so samples on a line give that
    line exactly).  With two samples it is the straight line between them (Drake needs
    three for a cubic spline; a line is C^∞).  Before the first and after the last sample
    the target moves on with the spline's end velocity: x_r = x(t_end) + ẋ(t_end)(t − t_end),
    ẍ_r = x⃛_r = 0 (so x_r is C¹ there, its acceleration jumps to 0: an object that
    keeps going, not one that stops or bounces).

    ``evaluate`` does not call Drake: at construction every piece (the spline's, and the
    two extrapolations) is stored as a 4 × 12 matrix M with
    [x, ẋ, ẍ, x⃛](t) = [1, τ, τ², τ³] M,  τ = t − (start of the piece),
    so an evaluation is a bisection and one small product.
    """

    def __init__(self, time: Sequence[float], position: Sequence[Sequence[float]]):
        t = np.asarray(time, dtype=float)
        if t.ndim != 1 or len(t) < 2:
            raise ValueError(f"time: at least 2 sample times are needed, got {len(np.atleast_1d(t))}")
        if not np.all(np.isfinite(t)):
            raise ValueError("time: must be finite")
        if not np.all(np.diff(t) > 0.0):
            raise ValueError("time: must be strictly increasing")
        try:
            x = np.asarray(position, dtype=float)
        except (TypeError, ValueError):
            raise ValueError("position: must be a list of [x, y, z] samples") from None
        if x.ndim != 2 or x.shape[1] != 3:
            raise ValueError(f"position: each sample must be [x, y, z], got shape {x.shape}")
        if len(x) != len(t):
            raise ValueError(f"position: one sample per time is needed, got {len(x)} for {len(t)} times")
        if not np.all(np.isfinite(x)):
            raise ValueError("position: must be finite")
        self.time = t
        self.position = x
        if len(t) == 2:
            spline = PiecewisePolynomial.FirstOrderHold(t, x.T)
        else:
            spline = PiecewisePolynomial.CubicWithContinuousSecondDerivatives(t, x.T, False)
        self.trajectory = spline

        def derivatives(tau: float) -> np.ndarray:
            return np.array([spline.EvalDerivative(tau, k)[:, 0] for k in range(4)])

        pieces = []
        for i in range(len(t) - 1):
            # Taylor coefficients c_j = x^(j)(t_i) / j! of the cubic on [t_i, t_i+1)
            d = derivatives(t[i])
            d[0] = x[i]
            pieces.append(self._piece(d[0], d[1], d[2] / 2.0, d[3] / 6.0))
        v_start = spline.EvalDerivative(t[0], 1)[:, 0]
        v_end = spline.EvalDerivative(t[-1], 1)[:, 0]
        zero = np.zeros(3)
        before = self._piece(x[0], v_start, zero, zero)  # τ measured from t_0 (negative)
        after = self._piece(x[-1], v_end, zero, zero)
        # piece j covers [time[j-1], time[j]): piece 0 is before time[0], the last after time[-1]
        self._starts = [float(ti) for ti in t]
        self._pieces = [before, *pieces, after]
        self._tau_powers = np.ones(4)

    @staticmethod
    def _piece(c0, c1, c2, c3) -> np.ndarray:
        """M such that [1, τ, τ², τ³] M = [x, ẋ, ẍ, x⃛] for x = c0 + c1 τ + c2 τ² + c3 τ³."""
        z = np.zeros(3)
        return np.array([np.concatenate([c0, c1, 2.0 * c2, 6.0 * c3]),
                         np.concatenate([c1, 2.0 * c2, 6.0 * c3, z]),
                         np.concatenate([c2, 3.0 * c3, z, z]),
                         np.concatenate([c3, z, z, z])])

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t."""
        j = bisect.bisect_right(self._starts, t)  # 0 before time[0]; len(time) from time[-1] on
        tau = t - self._starts[max(j - 1, 0)]
        p = self._tau_powers
        p[1] = tau
        p[2] = tau * tau
        p[3] = p[2] * tau
        return p @ self._pieces[j]
