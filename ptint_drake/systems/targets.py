"""Moving targets x_r(t) (SPEC section 5.2) and the Drake source that emits them.

Both kinds are functions of absolute time t:

- ``SinusoidTarget``: x_r = center + amplitude ⊙ sin(ω t + phase)
  (the paper's curve, eq. 28, is center (0.24, 0, 0.3), amplitude 0.1,
  ω = 1.5, phase (0, π/2, 0));
- ``LinearTarget``: x_r = start + velocity · t (an object on a conveyor).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.systems.schedule import Schedule


@dataclass(frozen=True)
class SinusoidTarget:
    center: np.ndarray
    amplitude: np.ndarray
    omega: float
    phase: np.ndarray

    def __post_init__(self):
        for name in ("center", "amplitude", "phase"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        a, w = self.amplitude, self.omega
        # the k-th derivative of a sin(ωt + φ) is a ωᵏ sin(ωt + φ + kπ/2): one sin call for all 12
        object.__setattr__(self, "_offset", np.concatenate([self.center, np.zeros(9)]))
        object.__setattr__(self, "_gain", np.concatenate([a, a * w, a * w**2, a * w**3]))
        object.__setattr__(self, "_shift", np.concatenate(
            [self.phase + k * np.pi / 2 for k in range(4)]))

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t."""
        return self._offset + self._gain * np.sin(self.omega * t + self._shift)


@dataclass(frozen=True)
class LinearTarget:
    start: np.ndarray
    velocity: np.ndarray

    def __post_init__(self):
        for name in ("start", "velocity"):
            object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=float))
        object.__setattr__(self, "_offset", np.concatenate([self.start, self.velocity, np.zeros(6)]))
        object.__setattr__(self, "_rate", np.concatenate([self.velocity, np.zeros(9)]))

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] stacked (12 values) at time t."""
        return self._offset + self._rate * t


def active_target_state(schedule: Schedule, targets: Sequence, t: float) -> np.ndarray:
    """[x_r, ẋ_r, ẍ_r, x⃛_r] of the target of the segment active at t (the first before it)."""
    return targets[max(schedule.active(t), 0)].evaluate(t)


class TargetSource(LeafSystem):
    """x_r, ẋ_r, ẍ_r of the target of the active segment (one target per segment).

    Output ports ``x_r``, ``xdot_r``, ``xddot_r`` (3 each) and ``target`` (the three
    stacked, 9) depend on time only.
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
            "x_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[0:3]),
            prerequisites_of_calc=time_only)
        self._xdot_out = self.DeclareVectorOutputPort(
            "xdot_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[3:6]),
            prerequisites_of_calc=time_only)
        self._xddot_out = self.DeclareVectorOutputPort(
            "xddot_r", 3, lambda c, o: o.SetFromVector(self._eval(c)[6:9]),
            prerequisites_of_calc=time_only)
        self._target_out = self.DeclareVectorOutputPort(
            "target", 9, lambda c, o: o.SetFromVector(self._eval(c)[0:9]),
            prerequisites_of_calc=time_only)
        self._objects_out = self.DeclareVectorOutputPort(
            "objects", 3 * len(targets),
            lambda c, o: o.SetFromVector(
                np.concatenate([tg.evaluate(c.get_time())[0:3] for tg in self._targets])),
            prerequisites_of_calc=time_only)

    @property
    def targets(self):
        return self._targets

    def evaluate(self, t: float) -> np.ndarray:
        """[x_r, ẋ_r, ẍ_r, x⃛_r] of the target active at absolute time t."""
        return active_target_state(self._schedule, self._targets, t)

    def get_x_r_output_port(self):
        return self._x_out

    def get_xdot_r_output_port(self):
        return self._xdot_out

    def get_xddot_r_output_port(self):
        return self._xddot_out

    def get_objects_output_port(self):
        return self._objects_out
