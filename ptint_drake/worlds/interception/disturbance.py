"""Joint torques the controller does not know about: d(t) and Coulomb friction.

The paper's disturbance d (its eq. 1) lumps friction, model error and external
torques.  Drake ignores URDF ``<dynamics friction>``, so Coulomb friction is
applied here through the plant's ``applied_generalized_force`` input with a
smooth law −F tanh(v / v_s); the external torque is a sinusoid plus a step:

    τ_ext = a ⊙ sin(2π f t + φ) + b ⊙ [t ≥ t_step] − F ⊙ tanh(v / v_s)

The law is a ``SymbolicVectorSystem`` (evaluated in C++: no Python runs per derivative
evaluation); terms whose coefficient is zero are left out of the expression.  It carries
one constant continuous state (ż = 0, always 0: zero error in any integrator's error norm).
"""

from __future__ import annotations

import numpy as np
from pydrake.symbolic import Expression, MakeVectorVariable, Variable, if_then_else, sin, tanh
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import SymbolicVectorSystem


def _per_joint(values, nv: int, name: str) -> np.ndarray:
    if len(values) == 0:
        return np.zeros(nv)
    if len(values) != nv:
        raise ValueError(f"{name}: needs one value per joint ({nv}), got {len(values)}")
    return np.asarray(values, dtype=float)


class JointDisturbance(Diagram):
    """Input ``state`` ([q; v]); output ``generalized_force`` (nv) = τ_ext above (N·m or N
    per generalized velocity).  ``torque(t, v)`` is the same law in numpy."""

    def __init__(self, nq: int, nv: int, amplitude=(), frequency_hz: float = 1.0, phase=(),
                 step=(), step_time: float = 0.0, coulomb=(), coulomb_speed: float = 0.01):
        super().__init__()
        self._nq = nq
        self._a = _per_joint(amplitude, nv, "plant.disturbance.amplitude")
        self._phase = _per_joint(phase, nv, "plant.disturbance.phase")
        self._b = _per_joint(step, nv, "plant.disturbance.step")
        self._F = _per_joint(coulomb, nv, "plant.coulomb")
        self._w = 2.0 * np.pi * frequency_hz
        self._t_step = step_time
        self._vs = coulomb_speed
        builder = DiagramBuilder()
        law = builder.AddNamedSystem("law", self._symbolic_law(nq, nv))
        builder.ExportInput(law.get_input_port(), "state")
        builder.ExportOutput(law.get_output_port(), "generalized_force")
        builder.BuildInto(self)

    def _symbolic_law(self, nq: int, nv: int) -> SymbolicVectorSystem:
        """τ_ext as a C++ system of time and [q; v] (zero coefficients give no term)."""
        t = Variable("t")
        x = MakeVectorVariable(nq + nv, "x")
        out = []
        for i in range(nv):
            term = Expression(0.0)
            if self._a[i] != 0.0:
                term = term + self._a[i] * sin(self._w * t + self._phase[i])
            if self._F[i] != 0.0:
                term = term - self._F[i] * tanh(x[nq + i] / self._vs)
            if self._b[i] != 0.0:
                term = term + if_then_else(t >= self._t_step, Expression(self._b[i]), Expression(0.0))
            out.append(term)
        # one dummy continuous state (ż = 0): a SymbolicVectorSystem without dynamics fails
        # when a Simulator asks every subsystem for its derivatives
        z = Variable("z")
        return SymbolicVectorSystem(time=t, state=[z], input=x, dynamics=[Expression(0.0)], output=out)

    def torque(self, t: float, v: np.ndarray) -> np.ndarray:
        """τ_ext at time t and joint velocities v (numpy; the system computes the same)."""
        tau = self._a * np.sin(self._w * t + self._phase) - self._F * np.tanh(v / self._vs)
        if t >= self._t_step:
            tau = tau + self._b
        return tau

    @staticmethod
    def needed(plant_config) -> bool:
        d = plant_config.disturbance
        return any(np.any(np.asarray(x) != 0) for x in (d.amplitude, d.step, plant_config.coulomb))
