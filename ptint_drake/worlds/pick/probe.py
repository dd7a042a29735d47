"""``PickProbe`` — what the pick metrics need from the plant at each logged instant.

For every part k, 10 values: its centre (3, m), its orientation as a quaternion (4, w x y z), and
three contact flags (1 or 0): its contact with the left pad, with the right pad, and with any other
body of the arm or the gripper.  Then a flag: any contact of the arm or the gripper with a belt;
and last the tool frame's pose (7: its origin, the fingertip centre, and quaternion).
Contacts are read from the plant's ``contact_results`` (point pairs and hydroelastic
surfaces, through the model's geometry-to-body map), poses from ``body_poses``.

``grip_forces``: per part k, [left, right] — the contact force of each pad on the part along the
closing axis (the tool frame's x axis, across the fingers: the pads' face normal), |f · x| summed
over that pad's contacts (N).  A squeeze shows on both pads; a finger resting on the part's top
shows a force along z and hardly any here.  The metrics' grip force is the smaller of the two
(what squeezes the part between the pads); the plant's truth, for metrics and tests only.

==================  ===========  ======================================================
port                size         meaning
==================  ===========  ======================================================
``contact_results`` —            input: the plant's ContactResults
``body_poses``      —            input: the plant's body poses
``probe``           10 · n + 8   output: per part [p, quat, left, right, other], belt, tool
``grip_forces``     2 · n        output: per part [left, right] pad force along the closing axis (N)
==================  ===========  ======================================================
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import LeafSystem

PART_WIDTH = 10  # values per part in the probe's output
LEFT, RIGHT, OTHER = 7, 8, 9  # the contact flags' places in a part's block
BELT = -8  # the belt flag's place; the tool's pose is the last 7 values


class PickProbe(LeafSystem):
    """Part poses and contact flags (module docstring).  ``parts``, ``belts``: body indices in
    config order; ``left``, ``right``: the pads' bodies; ``robot``: every arm and gripper body;
    ``body_of_geometry``: a GeometryId → body index map (for hydroelastic contacts); ``tool``: the
    tool frame's body index and its pose in that body (RigidTransform)."""

    def __init__(self, parts, belts, left: int, right: int, robot, body_of_geometry: dict, tool):
        super().__init__()
        self._parts = [int(b) for b in parts]
        self._part_slot = {b: k for k, b in enumerate(self._parts)}
        self._belts = {int(b) for b in belts}
        self._left, self._right = int(left), int(right)
        self._robot = {int(b) for b in robot}
        self._geometry = body_of_geometry
        self._tool_body, self._X_BT = int(tool[0]), tool[1]
        self._contacts = self.DeclareAbstractInputPort("contact_results",
                                                       AbstractValue.Make(ContactResults()))
        self._poses = self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        self.DeclareVectorOutputPort("probe", PART_WIDTH * len(self._parts) + 8, self._calc)
        self.DeclareVectorOutputPort("grip_forces", 2 * len(self._parts), self._calc_forces)

    def _pairs(self, results, forces: bool = False):
        """(body A, body B) of every contact, with the force on B (world, N) if ``forces``."""
        for i in range(results.num_point_pair_contacts()):
            info = results.point_pair_contact_info(i)
            yield (int(info.bodyA_index()), int(info.bodyB_index()),
                   np.array(info.contact_force()) if forces else None)
        for i in range(results.num_hydroelastic_contacts()):
            info = results.hydroelastic_contact_info(i)
            surface = info.contact_surface()
            force = None
            if forces:
                F_Ac_W = info.F_Ac_W()
                force = -np.array(F_Ac_W.translational())  # on N's body: −(on M's)
            yield self._geometry[surface.id_M()], self._geometry[surface.id_N()], force

    def _calc_forces(self, context, output) -> None:
        out = np.zeros(output.size())
        poses = self._poses.Eval(context)
        X_WT = poses[self._tool_body] @ self._X_BT
        x_tool = np.array(X_WT.rotation().matrix()[:, 0])  # a copy while X_WT lives (Drake 1.51's views)
        pads = {self._left: 0, self._right: 1}
        for a, b, f in self._pairs(self._contacts.Eval(context), forces=True):
            if a in self._part_slot and b in pads:
                out[2 * self._part_slot[a] + pads[b]] += abs(float(np.dot(f, x_tool)))
            elif b in self._part_slot and a in pads:
                out[2 * self._part_slot[b] + pads[a]] += abs(float(np.dot(f, x_tool)))
        output.SetFromVector(out)

    def _flag(self, out: np.ndarray, a: int, b: int) -> None:
        if b in self._part_slot and a in self._robot:
            a, b = b, a
        if a in self._part_slot and b in self._robot:
            where = {self._left: LEFT, self._right: RIGHT}.get(b, OTHER)
            out[PART_WIDTH * self._part_slot[a] + where] = 1.0
        elif (a in self._robot and b in self._belts) or (b in self._robot and a in self._belts):
            out[BELT] = 1.0

    def _calc(self, context, output) -> None:
        out = np.zeros(output.size())
        poses = self._poses.Eval(context)
        for k, body in enumerate(self._parts):
            X = poses[body]
            out[PART_WIDTH * k: PART_WIDTH * k + 3] = X.translation()
            out[PART_WIDTH * k + 3: PART_WIDTH * k + 7] = X.rotation().ToQuaternion().wxyz()
        X_WT = poses[self._tool_body] @ self._X_BT
        out[-7:-4], out[-4:] = X_WT.translation(), X_WT.rotation().ToQuaternion().wxyz()
        for a, b, _ in self._pairs(self._contacts.Eval(context)):
            self._flag(out, a, b)
        output.SetFromVector(out)
