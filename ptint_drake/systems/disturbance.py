"""Joint torques the controller does not know about: d(t) and Coulomb friction.

The paper's disturbance d (its eq. 1) lumps friction, model error and external
torques.  Drake ignores URDF ``<dynamics friction>``, so Coulomb friction is
applied here through the plant's ``applied_generalized_force`` input with a
smooth law −F tanh(v / v_s); the external torque is a sinusoid plus a step:

    τ_ext = a ⊙ sin(2π f t + φ) + b ⊙ [t ≥ t_step] − F ⊙ tanh(v / v_s)
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem


def _per_joint(values, nv: int, name: str) -> np.ndarray:
    if len(values) == 0:
        return np.zeros(nv)
    if len(values) != nv:
        raise ValueError(f"{name}: needs one value per joint ({nv}), got {len(values)}")
    return np.asarray(values, dtype=float)


class JointDisturbance(LeafSystem):
    """Input ``state`` ([q; v]); output ``generalized_force`` (nv) = τ_ext above."""

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
        self._state_in = self.DeclareVectorInputPort("state", nq + nv)
        self.DeclareVectorOutputPort("generalized_force", nv, self._calc)

    def torque(self, t: float, v: np.ndarray) -> np.ndarray:
        tau = self._a * np.sin(self._w * t + self._phase) - self._F * np.tanh(v / self._vs)
        if t >= self._t_step:
            tau = tau + self._b
        return tau

    def _calc(self, context, output):
        v = self._state_in.Eval(context)[self._nq:]
        output.SetFromVector(self.torque(context.get_time(), v))

    @staticmethod
    def needed(plant_config) -> bool:
        d = plant_config.disturbance
        return any(np.any(np.asarray(x) != 0) for x in (d.amplitude, d.step, plant_config.coulomb))
