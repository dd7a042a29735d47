"""A controller plugin for ptint_drake: a task-space PD, model-free (kinematics only).

    ptint run curve_b075_tf15 --set controller.type=task_space_pd:TaskSpacePD
    ptint compare curve_b075_tf15 --controllers ptsmc,task_space_pd:TaskSpacePD
"""
import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import LeafSystem


class TaskSpacePD(LeafSystem):
    """τ = Jᵀ (Kp (x_r − x) + Kd (ẋ_r − ẋ)); ``params``: Kp (N/m), Kd (N·s/m)."""

    def __init__(self, plant, end_effector, params):
        super().__init__()
        self._plant, self._context = plant, plant.CreateDefaultContext()
        self._frame = plant.GetFrameByName(end_effector)
        self._Kp, self._Kd = float(params.get("Kp", 2000.0)), float(params.get("Kd", 150.0))
        self._B_T = plant.MakeActuationMatrix().T
        self._state = self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self._target = self.DeclareVectorInputPort("target", 9)  # x_r, ẋ_r, ẍ_r
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(), self._actuation)

    def _actuation(self, context, output):
        plant, ctx = self._plant, self._context
        plant.SetPositionsAndVelocities(ctx, self._state.Eval(context))
        target = self._target.Eval(context)
        x = self._frame.CalcPoseInWorld(ctx).translation()
        J = plant.CalcJacobianTranslationalVelocity(ctx, JacobianWrtVariable.kV, self._frame,
                                                    np.zeros(3), plant.world_frame(), plant.world_frame())
        xdot = J @ plant.GetVelocities(ctx)
        force = self._Kp * (target[0:3] - x) + self._Kd * (target[3:6] - xdot)
        output.SetFromVector(self._B_T @ (J.T @ force))
