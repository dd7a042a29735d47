"""``PartPoses`` — every part's *simulated* motion, in the shape of a target.

The interceptor's target for a pick is where the part really is as it rides its belt (a belt
that runs fast, or a part that slipped, is a real disturbance), so this system reads the plant's
outputs rather than any formula.  For part k (a free body; its origin = the part's centre):

============================  ====  ============================================================
port                          size  meaning
============================  ====  ============================================================
``body_poses``                —     input: the plant's ``body_poses`` (list of RigidTransform)
``state``                     —     input: the plant's whole state [q; v]
``generalized_accelerations`` —     input: the plant's v̇
``part_k_pose``               9     output: [x, ẋ, ẍ] of the centre in world (m, m/s, m/s²), the
                                    layout of a ``target`` port (``signals.TARGET_PORT``)
``part_k_rotation``           15    output: [R (row-major), ω, ω̇] of the part frame in world
                                    (rad/s, rad/s²), the layout of a ``target_rotation`` port
============================  ====  ============================================================

A free body's generalized coordinates are its pose and motion in world: q = [quaternion (w x y
z); p_WB], v = [ω_WB; v_WB], v̇ = [α_WB; a_WB] — the very numbers of its entries in the plant's
``body_poses`` (translation), ``spatial_velocities`` and ``spatial_accelerations``
(tests/unit/test_pick_world.py compares them bit for bit), read here from two vector ports
instead of three lists of every body (on Drake 1.51's bindings each list costs 9–12 µs to hand
to Python, a vector port about 1 µs).  The rotation matrix is the body pose's: the plant's
quaternion drifts from unit norm over a run, which pydrake's ``Quaternion`` refuses.

The accelerations are the discrete plant's (finite differences of one 1 ms step), so they carry
the contact's chatter; a consumer that differentiates them further should filter first.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.framework import LeafSystem


class PartPoses(LeafSystem):
    """Outputs ``part_k_pose`` (9) and ``part_k_rotation`` (15) for the free bodies ``parts``
    of ``plant`` (in that order, k = 0, 1, …); see the module docstring.  The plant is read at
    build time only (each body's index and the places of its coordinates in [q; v])."""

    def __init__(self, plant, parts):
        super().__init__()
        nq, nv = plant.num_positions(), plant.num_velocities()
        self._poses = self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        self._state = self.DeclareVectorInputPort("state", nq + nv)
        self._accelerations = self.DeclareVectorInputPort("generalized_accelerations", nv)
        for k, body in enumerate(parts):
            q0, v0 = body.floating_positions_start(), body.floating_velocities_start_in_v()
            where = (int(body.index()), slice(q0 + 4, q0 + 7), slice(nq + v0, nq + v0 + 3),
                     slice(nq + v0 + 3, nq + v0 + 6), slice(v0, v0 + 3), slice(v0 + 3, v0 + 6))
            # the inputs alone (not the time): a logger's sample between two plant steps reuses them
            inputs = {self.all_input_ports_ticket()}
            self.DeclareVectorOutputPort(f"part_{k}_pose", 9, self._pose_calc(where), inputs)
            self.DeclareVectorOutputPort(f"part_{k}_rotation", 15, self._rotation_calc(where), inputs)

    def _pose_calc(self, where):
        _, p, _, v, _, a = where

        def calc(context, output):
            x, vdot = self._state.Eval(context), self._accelerations.Eval(context)
            output.SetFromVector(np.concatenate([x[p], x[v], vdot[a]]))
        return calc

    def _rotation_calc(self, where):
        body, _, w, _, alpha, _ = where

        def calc(context, output):
            X = self._poses.Eval(context)[body]  # held while its rotation is read (Drake 1.51's views)
            x, vdot = self._state.Eval(context), self._accelerations.Eval(context)
            output.SetFromVector(np.concatenate([X.rotation().matrix().ravel(), x[w], vdot[alpha]]))
        return calc
