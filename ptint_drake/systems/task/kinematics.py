"""Task-space kinematics of one frame of any MultibodyPlant (paper eq. 5).

    x = f(q),  ẋ = J(q) q̇

x is the position in the world of the origin of a frame (the interception
point), J its translational Jacobian with respect to the plant's generalized
velocities.  A serial chain of revolute and prismatic joints is computed by
compiled code (``chain.KinematicChain``, equal to Drake's to rounding); anything
else by the plant.  Kinematics only: no mass matrix, Coriolis or gravity term is ever
evaluated here, which is what keeps the controller model-free.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.chain import KinematicChain
from ptint_drake.systems.task.error import task_jacobian

_ORIGIN = np.zeros(3)


class FrameKinematics:
    """x, ẋ, J of one frame's origin (paper eq. 5): by the compiled ``chain`` when the frame ends a
    serial revolute/prismatic chain, otherwise by the plant on a private context."""

    def __init__(self, plant, frame):
        self.chain = KinematicChain.of(plant, frame)
        self._plant = plant
        self._frame = frame
        self._world = plant.world_frame()
        self._plant_context = plant.CreateDefaultContext()
        self._kV = JacobianWrtVariable.kV
        if self.chain is not None:  # numba loads the compiled chain now, not at a run's first step
            self.chain.evaluate(np.zeros(plant.num_positions()))

    def compute(self, q, v) -> tuple:
        """(x, ẋ, J) at joint positions q and velocities v: arrays of 3, 3 and 3 × nv."""
        if self.chain is not None:
            x, _, J, _ = self.chain.evaluate(q)
            return x, J @ v, J
        plant, pc = self._plant, self._plant_context
        plant.SetPositions(pc, q)
        x = self._frame.CalcPoseInWorld(pc).translation()
        J = plant.CalcJacobianTranslationalVelocity(
            pc, self._kV, self._frame, _ORIGIN, self._world, self._world)
        return x, J @ v, J

    def compute_pose(self, q, v) -> tuple:
        """(x, ẋ, R, ω, J_v, J_ω) at q, v: the frame's position, velocity, orientation (3 × 3),
        angular velocity (world frame) and the translational and rotational Jacobians (3 × nv)."""
        if self.chain is not None:
            x, R, J_v, J_w = self.chain.evaluate(q)
            return x, J_v @ v, R, J_w @ v, J_v, J_w
        plant, pc = self._plant, self._plant_context
        plant.SetPositions(pc, q)
        X = self._frame.CalcPoseInWorld(pc)
        Js = plant.CalcJacobianSpatialVelocity(pc, self._kV, self._frame, _ORIGIN, self._world, self._world)
        J_w, J_v = Js[0:3], Js[3:6]
        return X.translation(), J_v @ v, X.rotation().matrix(), J_w @ v, J_v, J_w


class TaskSpaceKinematics(LeafSystem):
    """Input ``state`` = [q; v] of the plant; outputs ``x`` (3), ``xdot`` (3), ``J`` (3·nv, row-major).

    With an orientation ``task`` (``pose``, ``top_down``) also ``R`` (the frame's orientation,
    row-major, 9) and ``omega`` (its angular velocity, 3), and ``J`` is the task's
    [J_v; c J_ω] (6·nv, ``task.task_jacobian``, c = ``rot_scale``).
    The system owns a private plant context: each change of the input writes it
    once and one cache entry computes everything together.
    """

    def __init__(self, plant, frame, task: str = "position", rot_scale: float = 0.1):
        super().__init__()
        self._kinematics = FrameKinematics(plant, frame)
        nq, nv = plant.num_positions(), plant.num_velocities()
        self._nq, self._nv = nq, nv
        self._rotation = task != "position"
        self._rot_scale = float(rot_scale)
        self._state_in = self.DeclareVectorInputPort("state", nq + nv)
        deps = {self._state_in.ticket()}
        parts = [("x", 3), ("xdot", 3)] + ([("R", 9), ("omega", 3), ("J", 6 * nv)] if self._rotation
                                           else [("J", 3 * nv)])
        size = sum(n for _, n in parts)
        self._eval = DeclareVectorCache(self, "kinematics", size, self._calc, deps)
        lo = 0
        for name, n in parts:
            self.DeclareVectorOutputPort(
                name, n, lambda c, o, part=slice(lo, lo + n): o.SetFromVector(self._eval(c)[part]),
                prerequisites_of_calc=deps)
            lo += n
        self._x_out, self._xdot_out, self._J_out = (self.GetOutputPort(n) for n in ("x", "xdot", "J"))

    @property
    def num_velocities(self) -> int:
        return self._nv

    def _calc(self, context) -> np.ndarray:
        qv = self._state_in.Eval(context)
        return self.evaluate(qv[: self._nq], qv[self._nq:])

    def evaluate(self, q, v) -> np.ndarray:
        """[x, ẋ, vec(J)] (row-major J, 3 × nv) at joint positions q and velocities v; with
        orientation [x, ẋ, vec(R), ω, vec([J_v; c J_ω])]."""
        if self._rotation:
            x, xdot, R, w, J_v, J_w = self._kinematics.compute_pose(q, v)
            return np.concatenate([x, xdot, R.ravel(), w, task_jacobian(J_v, J_w, self._rot_scale).ravel()])
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
