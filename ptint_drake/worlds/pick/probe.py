"""``PickProbe`` — what the pick metrics need from the plant at each logged instant.

For every part k, 10 values: its centre (3, m), its orientation as a quaternion (4, w x y z), and
three contact flags (1 or 0): its contact with the left pad, with the right pad, and with any other
body of the arm or the gripper.  Then a flag: any contact of the arm or the gripper with a belt;
and last the tool frame's pose (7: its origin, the fingertip centre, and quaternion).
Contacts are read from the station's ``contact_pairs`` (``contact_pairs.ContactPairs``: the
bodies of every point pair and hydroelastic surface, read once for this probe and the station's
``CollisionProbe``), the pads' forces from the plant's ``contact_results``, poses from
``body_poses``.  Both outputs come from one cache entry: the loggers ask for them at the same
instants, and the contacts and poses are read once for both.

``grip_forces``: per part k, [left, right] — the contact force of each pad on the part along the
closing axis (the tool frame's x axis, across the fingers: the pads' face normal), |f · x| summed
over that pad's contacts (N).  A squeeze shows on both pads; a finger resting on the part's top
shows a force along z and hardly any here.  The metrics' grip force is the smaller of the two
(what squeezes the part between the pads); the plant's truth, for metrics and tests only.

==================  ===========  ======================================================
port                size         meaning
==================  ===========  ======================================================
``contact_pairs``   —            input: (body A, body B, where) per contact (``ContactPairs``)
``contact_results`` —            input: the plant's ContactResults (the pads' forces)
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

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.worlds.pick.contact_pairs import contact_force

PART_WIDTH = 10  # values per part in the probe's output
LEFT, RIGHT, OTHER = 7, 8, 9  # the contact flags' places in a part's block
BELT = -8  # the belt flag's place; the tool's pose is the last 7 values


class PickProbe(LeafSystem):
    """Part poses and contact flags (module docstring).  ``parts``, ``belts``: body indices in
    config order; ``left``, ``right``: the pads' bodies; ``robot``: every arm and gripper body;
    ``tool``: the tool frame's body index and its pose in that body (RigidTransform)."""

    def __init__(self, parts, belts, left: int, right: int, robot, tool):
        super().__init__()
        self._parts = [int(b) for b in parts]
        self._part_slot = {b: k for k, b in enumerate(self._parts)}
        self._belts = {int(b) for b in belts}
        self._left, self._right = int(left), int(right)
        self._pads = {self._left: 0, self._right: 1}
        self._robot = {int(b) for b in robot}
        self._tool_body, self._X_BT = int(tool[0]), tool[1]
        self._pairs = self.DeclareAbstractInputPort("contact_pairs", AbstractValue.Make(()))
        self._contacts = self.DeclareAbstractInputPort("contact_results",
                                                       AbstractValue.Make(ContactResults()))
        self._poses = self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        n = PART_WIDTH * len(self._parts) + 8
        self._values = DeclareVectorCache(self, "probe and grip forces", n + 2 * len(self._parts),
                                          self._calc_values, {self.all_input_ports_ticket()})
        self._probe = slice(0, n)
        self._forces = slice(n, n + 2 * len(self._parts))
        self.DeclareVectorOutputPort("probe", n, lambda c, o: o.SetFromVector(self._values(c)[self._probe]))
        self.DeclareVectorOutputPort("grip_forces", 2 * len(self._parts),
                                     lambda c, o: o.SetFromVector(self._values(c)[self._forces]))

    def _calc_values(self, context) -> np.ndarray:
        """[probe; grip_forces] (module docstring), the contacts and poses read once."""
        n = PART_WIDTH * len(self._parts) + 8
        out = np.zeros(n + 2 * len(self._parts))
        poses = self._poses.Eval(context)
        for k, body in enumerate(self._parts):
            X = poses[body]
            out[PART_WIDTH * k: PART_WIDTH * k + 3] = X.translation()
            out[PART_WIDTH * k + 3: PART_WIDTH * k + 7] = X.rotation().ToQuaternion().wxyz()
        X_WT = poses[self._tool_body] @ self._X_BT
        R_WT = X_WT.rotation()
        out[n - 7:n - 4], out[n - 4:n] = X_WT.translation(), R_WT.ToQuaternion().wxyz()
        x_tool = None
        results = None
        slot, pads, robot = self._part_slot, self._pads, self._robot
        for a, b, where in self._pairs.Eval(context):
            if b in slot and a in robot:
                a, b = b, a
            if a in slot and b in robot:
                k = slot[a]
                pad = pads.get(b)
                out[PART_WIDTH * k + (OTHER if pad is None else LEFT + pad)] = 1.0
                if pad is not None:  # a pad on a part: its force along the closing axis
                    if x_tool is None:
                        x_tool = np.array(R_WT.matrix()[:, 0])  # a copy while R_WT lives (Drake 1.51's views)
                        results = self._contacts.Eval(context)
                    f = contact_force(results, where)
                    out[n + 2 * k + pad] += abs(float(np.dot(f, x_tool)))
            elif (a in robot and b in self._belts) or (b in robot and a in self._belts):
                out[n + BELT] = 1.0
        return out
