"""The camera path's target: the active object's estimate, extrapolated to t, compiled.

``imm.AdaptiveTargetEstimator`` stores its output as a polynomial in time (its ``polynomial``
state [t_est, c₀, c₁, c₂]: target = c₀ + Δt c₁ + Δt² c₂, Δt = t − t_est) and exports that
state on a C++ port.  ``PolynomialTargetSelector`` reads the active segment's polynomial (the
segment of ``schedule.active(t)``, the first before any start) and evaluates it with one
compiled kernel (``polynomial_target``): one Python entry per derivative evaluation between
the filters and the controller, and only the active estimator's port is evaluated.

Measured (``bench --floors`` and the selector alone, µs per output evaluation from Python,
Drake 1.51.1 / 1.58): a Drake ``SymbolicVectorSystem`` of the same law (its expressions
evaluated in C++ against an environment of every input variable) cost 4.1 / 3.8 for one
object, 5.7 / 5.3 for two and 7.3 / 7.3 for three; this leaf 2.8 / 2.6, 3.2 / 2.7 and
3.2 / 2.7 (the earlier ``kalman.ActiveTargetSelector`` + the filters' Python outputs did two
entries).  Same ports as ``ActiveTargetSelector``; the values equal the estimator's ``target``
output to rounding.
"""

from __future__ import annotations

from numba import njit
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.schedule import Schedule
from ptint_drake.systems.signals import TARGET_PORT_SIZE

POLYNOMIAL_SIZE = 1 + 3 * TARGET_PORT_SIZE  # [t_est, c₀, c₁, c₂]


@njit(cache=True)
def polynomial_target(t: float, c, out) -> None:
    """``out`` (9) ← c₀ + Δt c₁ + Δt² c₂, Δt = t − t_est, of c = [t_est, c₀, c₁, c₂] (28)."""
    dt = t - c[0]
    for k in range(TARGET_PORT_SIZE):
        out[k] = c[1 + k] + dt * c[1 + TARGET_PORT_SIZE + k] + (dt * dt) * c[1 + 2 * TARGET_PORT_SIZE + k]


class PolynomialTargetSelector(LeafSystem):
    """Input ports ``target_0`` … ``target_{count-1}`` (each an estimator's ``polynomial``,
    ``POLYNOMIAL_SIZE``); output ``target`` (9): [x_r, ẋ_r, ẍ_r] of the active segment's
    object at t (``polynomial_target``)."""

    def __init__(self, *, schedule: Schedule, count: int):
        super().__init__()
        if count != len(schedule):
            raise ValueError(f"count: one target per segment is needed, got {count} "
                             f"for {len(schedule)} segments")
        self._schedule = schedule
        self._inputs = [self.DeclareVectorInputPort(f"target_{i}", POLYNOMIAL_SIZE) for i in range(count)]
        self._target_out = self.DeclareVectorOutputPort(
            "target", TARGET_PORT_SIZE, self._calc,
            prerequisites_of_calc={self.time_ticket(), self.all_input_ports_ticket()})

    def get_target_output_port(self):
        return self._target_out

    def _calc(self, context, output) -> None:
        t = context.get_time()
        i = max(self._schedule.active(t), 0)
        polynomial_target(t, self._inputs[i].EvalBasicVector(context).value(), output.get_mutable_value())
