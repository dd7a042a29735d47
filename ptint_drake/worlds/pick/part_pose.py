"""``PartPoses`` — every part's *simulated* motion, in the shape of a target.

The interceptor's target for a pick is where the part really is as it rides its belt (a belt
that runs fast, or a part that slipped, is a real disturbance), so this system reads the plant's
body outputs rather than any formula.  For part k (its body's origin = the part's centre):

=====================  ====  ===================================================================
port                   size  meaning
=====================  ====  ===================================================================
``body_poses``         —     input: the plant's ``body_poses`` (list of RigidTransform)
``body_velocities``    —     input: the plant's ``spatial_velocities`` (list of SpatialVelocity)
``body_accelerations`` —     input: the plant's ``spatial_accelerations``
``part_k_pose``        9     output: [x, ẋ, ẍ] of the centre in world (m, m/s, m/s²), the layout
                             of a ``target`` port (``signals.TARGET_PORT``)
``part_k_rotation``    15    output: [R (row-major), ω, ω̇] of the part frame in world (rad/s,
                             rad/s²), the layout of a ``target_rotation`` port
=====================  ====  ===================================================================

The accelerations are the discrete plant's (finite differences of one 1 ms step), so they carry
the contact's chatter; a consumer that differentiates them further should filter first.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialAcceleration, SpatialVelocity
from pydrake.systems.framework import LeafSystem


class PartPoses(LeafSystem):
    """Outputs ``part_k_pose`` (9) and ``part_k_rotation`` (15) for the bodies ``body_indices``
    (in that order, k = 0, 1, …); see the module docstring."""

    def __init__(self, body_indices: Sequence[int]):
        super().__init__()
        self._bodies = [int(i) for i in body_indices]
        self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        self.DeclareAbstractInputPort("body_velocities", AbstractValue.Make([SpatialVelocity()]))
        self.DeclareAbstractInputPort("body_accelerations", AbstractValue.Make([SpatialAcceleration()]))
        for k, body in enumerate(self._bodies):
            self.DeclareVectorOutputPort(f"part_{k}_pose", 9, self._pose_calc(body))
            self.DeclareVectorOutputPort(f"part_{k}_rotation", 15, self._rotation_calc(body))

    def _inputs(self, context, body: int):
        return (self.get_input_port(0).Eval(context)[body], self.get_input_port(1).Eval(context)[body],
                self.get_input_port(2).Eval(context)[body])

    def _pose_calc(self, body: int):
        def calc(context, output):
            X, V, A = self._inputs(context, body)
            output.SetFromVector(np.concatenate([X.translation(), V.translational(), A.translational()]))
        return calc

    def _rotation_calc(self, body: int):
        def calc(context, output):
            X, V, A = self._inputs(context, body)
            output.SetFromVector(np.concatenate([X.rotation().matrix().ravel(), V.rotational(),
                                                 A.rotational()]))
        return calc
