"""The active object's target, chosen by time: ``ActiveTargetSelector`` (one for every estimator).

Every camera path ends in one selector: it reads the input of the segment active at t (the
segment of ``schedule.active(t)``, the first before any start) and either passes it on (a
``kalman.TargetKalmanFilter``'s ``target``, or a ``rotation_estimator.RotationEstimator``'s
``target_rotation``, 15 wide) or, with ``polynomial``, evaluates it.

``imm.AdaptiveTargetEstimator`` stores its output as a polynomial in time (its ``polynomial``
state [t_est, c₀, c₁, c₂]: target = c₀ + Δt c₁ + Δt² c₂, Δt = t − t_est) and exports that
state on a C++ port; the selector evaluates the active one with one compiled kernel
(``polynomial_target``): one Python entry per derivative evaluation between the filters and
the controller, and only the active estimator's port is evaluated.

Measured (``bench --floors`` and the selector alone, µs per output evaluation from Python,
Drake 1.51.1 / 1.58): a Drake ``SymbolicVectorSystem`` of the same law (its expressions
evaluated in C++ against an environment of every input variable) cost 4.1 / 3.8 for one
object, 5.7 / 5.3 for two and 7.3 / 7.3 for three; the polynomial selector 2.8 / 2.6,
3.2 / 2.7 and 3.2 / 2.7 (passing on the filters' Python ``target`` outputs did two entries).
The values equal the estimator's ``target`` output to rounding.
"""

from __future__ import annotations

from numba import njit
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET_PORT_SIZE

POLYNOMIAL_SIZE = 1 + 3 * TARGET_PORT_SIZE  # [t_est, c₀, c₁, c₂]


@njit(cache=True)
def polynomial_target(t: float, c, out) -> None:
    """``out`` (9) ← c₀ + Δt c₁ + Δt² c₂, Δt = t − t_est, of c = [t_est, c₀, c₁, c₂] (28)."""
    dt = t - c[0]
    for k in range(TARGET_PORT_SIZE):
        out[k] = c[1 + k] + dt * c[1 + TARGET_PORT_SIZE + k] + (dt * dt) * c[1 + 2 * TARGET_PORT_SIZE + k]


class ActiveTargetSelector(LeafSystem):
    """Input ports ``target_0`` … ``target_{count-1}``; output ``target`` (``size``, default 9:
    [x_r, ẋ_r, ẍ_r]): the input of the segment active at t (``schedule.active(t)``; the first
    before any start).

    Without ``polynomial`` the inputs are ``size`` wide and passed on (``size`` 15 selects
    orientations, ``signals.TARGET_ROTATION``); with it they are estimators' ``polynomial``
    states (``POLYNOMIAL_SIZE``) and the active one is evaluated at t (``polynomial_target``).
    """

    def __init__(self, *, schedule: Schedule, count: int, size: int = TARGET_PORT_SIZE,
                 polynomial: bool = False):
        super().__init__()
        if count != len(schedule):
            raise ValueError(f"count: one target per segment is needed, got {count} "
                             f"for {len(schedule)} segments")
        if polynomial and size != TARGET_PORT_SIZE:
            raise ValueError(f"size: a polynomial is evaluated into a target ({TARGET_PORT_SIZE}), "
                             f"got {size}")
        self._schedule = schedule
        width = POLYNOMIAL_SIZE if polynomial else size
        self._inputs = [self.DeclareVectorInputPort(f"target_{i}", width) for i in range(count)]
        self._target_out = self.DeclareVectorOutputPort(
            "target", size, self._calc_polynomial if polynomial else self._calc_value,
            prerequisites_of_calc={self.time_ticket(), self.all_input_ports_ticket()})

    def get_target_output_port(self):
        return self._target_out

    def _active(self, t: float) -> int:
        return max(self._schedule.active(t), 0) if len(self._inputs) > 1 else 0

    def _calc_value(self, context, output) -> None:
        output.SetFromVector(self._inputs[self._active(context.get_time())].Eval(context))

    def _calc_polynomial(self, context, output) -> None:
        t = context.get_time()
        polynomial_target(t, self._inputs[self._active(t)].EvalBasicVector(context).value(),
                          output.get_mutable_value())


class PolynomialTargetSelector(ActiveTargetSelector):
    """The earlier name of ``ActiveTargetSelector(polynomial=True)``, kept importable."""

    def __init__(self, *, schedule: Schedule, count: int):
        super().__init__(schedule=schedule, count=count, polynomial=True)
