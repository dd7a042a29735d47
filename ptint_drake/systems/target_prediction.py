"""The camera path's target in C++: the active object's estimate, extrapolated to t.

``imm.AdaptiveTargetEstimator`` stores its output as a polynomial in time (its ``polynomial``
state [t_est, c₀, c₁, c₂]: target = c₀ + Δt c₁ + Δt² c₂, Δt = t − t_est) and exports that
state on a C++ port.  ``PolynomialTargetSelector`` evaluates the active segment's polynomial
(the segment of ``schedule.active(t)``, the first before any start) as one Drake
``SymbolicVectorSystem``: no Python runs per derivative evaluation between the filters and
the controller (``kalman.ActiveTargetSelector`` + the filters' Python outputs did two entries).
Same ports as ``ActiveTargetSelector``; the values equal the estimator's ``target`` output to
rounding (the expression is evaluated in C++).
"""

from __future__ import annotations

from pydrake.symbolic import Expression, MakeVectorVariable, Variable, if_then_else
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Multiplexer, SymbolicVectorSystem

from ptint_drake.systems.schedule import Schedule
from ptint_drake.systems.signals import TARGET_PORT_SIZE

POLYNOMIAL_SIZE = 1 + 3 * TARGET_PORT_SIZE  # [t_est, c₀, c₁, c₂]


class PolynomialTargetSelector(Diagram):
    """Input ports ``target_0`` … ``target_{count-1}`` (each an estimator's ``polynomial``,
    ``POLYNOMIAL_SIZE``); output ``target`` (9): [x_r, ẋ_r, ẍ_r] of the active segment's
    object at t."""

    def __init__(self, *, schedule: Schedule, count: int):
        super().__init__()
        if count != len(schedule):
            raise ValueError(f"count: one target per segment is needed, got {count} "
                             f"for {len(schedule)} segments")
        builder = DiagramBuilder()
        law = builder.AddNamedSystem("polynomial", _selector_law(schedule.starts, count))
        if count == 1:
            builder.ExportInput(law.get_input_port(), "target_0")
        else:
            mux = builder.AddNamedSystem("inputs", Multiplexer([POLYNOMIAL_SIZE] * count))
            builder.Connect(mux.get_output_port(), law.get_input_port())
            for i in range(count):
                builder.ExportInput(mux.get_input_port(i), f"target_{i}")
        builder.ExportOutput(law.get_output_port(), "target")
        builder.BuildInto(self)

    def get_target_output_port(self):
        return self.GetOutputPort("target")


def _selector_law(starts, count: int) -> SymbolicVectorSystem:
    """target(t, u) = the polynomial of segment i in u, i the last with starts[i] ≤ t (0 before)."""
    t = Variable("t")
    u = MakeVectorVariable(POLYNOMIAL_SIZE * count, "u")
    n = TARGET_PORT_SIZE
    out = []
    for k in range(n):
        value = None
        for i in range(count):
            c = u[POLYNOMIAL_SIZE * i:POLYNOMIAL_SIZE * (i + 1)]
            dt = t - c[0]
            term = c[1 + k] + dt * c[1 + n + k] + (dt * dt) * c[1 + 2 * n + k]
            value = term if value is None else if_then_else(t >= starts[i], term, value)
        out.append(value)
    # one constant continuous state (ż = 0): a SymbolicVectorSystem without dynamics fails
    # when a Simulator asks every subsystem for its derivatives
    z = Variable("z")
    return SymbolicVectorSystem(time=t, state=[z], input=u, dynamics=[Expression(0.0)], output=out)
