"""Task-space kinematics of one frame of any MultibodyPlant (paper eq. 5).

    x = f(q),  ẋ = J(q) q̇

x is the position in the world of the origin of a frame (the interception
point), J its translational Jacobian with respect to the plant's generalized
velocities.  Kinematics only: no mass matrix, Coriolis or gravity term is ever
evaluated here, which is what keeps the controller model-free.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.cache import DeclareVectorCache


_ORIGIN = np.zeros(3)


class FrameKinematics:
    """x, ẋ, J of one frame's origin (paper eq. 5), computed on a private plant context."""

    def __init__(self, plant, frame):
        self._plant = plant
        self._frame = frame
        self._world = plant.world_frame()
        self._plant_context = plant.CreateDefaultContext()
        self._kV = JacobianWrtVariable.kV

    def compute(self, q, v) -> tuple:
        """(x, ẋ, J) at joint positions q and velocities v: arrays of 3, 3 and 3 × nv."""
        plant, pc = self._plant, self._plant_context
        plant.SetPositions(pc, q)
        x = self._frame.CalcPoseInWorld(pc).translation()
        J = plant.CalcJacobianTranslationalVelocity(
            pc, self._kV, self._frame, _ORIGIN, self._world, self._world)
        return x, J @ v, J


class TaskSpaceKinematics(LeafSystem):
    """Input ``state`` = [q; v] of the plant; outputs ``x`` (3), ``xdot`` (3), ``J`` (3·nv, row-major).

    The system owns a private plant context: each change of the input writes it
    once and one cache entry computes x, ẋ and J together.
    """

    def __init__(self, plant, frame):
        super().__init__()
        self._kinematics = FrameKinematics(plant, frame)
        nq, nv = plant.num_positions(), plant.num_velocities()
        self._nq, self._nv = nq, nv
        self._state_in = self.DeclareVectorInputPort("state", nq + nv)
        deps = {self._state_in.ticket()}
        self._eval = DeclareVectorCache(self, "kinematics", 6 + 3 * nv, self._calc, deps)
        self._x_out = self.DeclareVectorOutputPort(
            "x", 3, lambda c, o: o.SetFromVector(self._eval(c)[0:3]), prerequisites_of_calc=deps)
        self._xdot_out = self.DeclareVectorOutputPort(
            "xdot", 3, lambda c, o: o.SetFromVector(self._eval(c)[3:6]), prerequisites_of_calc=deps)
        self._J_out = self.DeclareVectorOutputPort(
            "J", 3 * nv, lambda c, o: o.SetFromVector(self._eval(c)[6:]), prerequisites_of_calc=deps)

    @property
    def num_velocities(self) -> int:
        return self._nv

    def _calc(self, context) -> np.ndarray:
        qv = self._state_in.Eval(context)
        return self.evaluate(qv[: self._nq], qv[self._nq:])

    def evaluate(self, q, v) -> np.ndarray:
        """[x, ẋ, vec(J)] (row-major J, 3 × nv) at joint positions q and velocities v."""
        x, xdot, J = self._kinematics.compute(q, v)
        return np.concatenate([x, xdot, J.ravel()])

    def get_state_input_port(self):
        return self._state_in

    def get_x_output_port(self):
        return self._x_out

    def get_xdot_output_port(self):
        return self._xdot_out

    def get_J_output_port(self):
        return self._J_out
