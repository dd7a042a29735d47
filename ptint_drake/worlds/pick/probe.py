"""``PickProbe`` — what the pick metrics need from the plant at each logged instant, in one vector.

For every part k, 10 values: its centre (3, m), its orientation as a quaternion (4, w x y z), and
three contact flags (1 or 0): its contact with the left pad, with the right pad, and with any other
body of the arm or the gripper.  Then a flag: any contact of the arm or the gripper with a belt;
and last the tool frame's pose (7: its origin, the fingertip centre, and quaternion).  That is the
``probe`` block (``PROBE``); then the ``grip_forces`` block and the ``collisions`` block.

``grip_forces``: per part k, [left, right] — the contact force of each pad on the part along the
closing axis (the tool frame's x axis, across the fingers: the pads' face normal), |f · x| summed
over that pad's contacts (N).  A squeeze shows on both pads; a finger resting on the part's top
shows a force along z and hardly any here.  The metrics' grip force is the smaller of the two
(what squeezes the part between the pads); the plant's truth, for metrics and tests only.

``collisions``: per obstacle of the station's ``CollisionProbe`` (belts, tray, floor, parts; its
order) [finger contact, other robot contact] — the station's ``collisions`` port, computed here
from the same reading of the contacts.

Contacts are read from the plant's ``contact_results`` once per evaluation (each contact's
bodies, and the force of a pad–part contact from the same record: a binding call per contact and
field, about 3 µs a contact on Drake 1.51's bindings), poses from ``body_poses``.  One output,
one logger (``run.build_pick`` splits the log into ``probe``, ``grip_forces`` and ``collisions``
by ``PickProbe.blocks``): the three were three systems, two cache readers and three loggers,
each sample paying for every hop.

==================  ===========  ======================================================
port                size         meaning
==================  ===========  ======================================================
``contact_results`` —            input: the plant's ContactResults
``body_poses``      —            input: the plant's body poses
``values``          see above    output: [probe (10·n + 8); grip_forces (2·n); collisions (2·m)]
==================  ===========  ======================================================
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.multibody.plant import ContactResults
from pydrake.systems.framework import LeafSystem

from ptint_drake.worlds.pick.collisions import FINGER, OTHER as OBSTACLE_OTHER, CollisionProbe
from ptint_drake.worlds.pick.contact_pairs import contact_force

PART_WIDTH = 10  # values per part in the probe's output
LEFT, RIGHT, OTHER = 7, 8, 9  # the contact flags' places in a part's block
BELT = -8  # the belt flag's place; the tool's pose is the last 7 values


class PickProbe(LeafSystem):
    """Part poses, contact flags, pad forces and collision flags (module docstring).  ``parts``,
    ``belts``: body indices in config order; ``left``, ``right``: the pads' bodies; ``robot``:
    every arm and gripper body; ``tool``: the tool frame's body index and its pose in that body
    (RigidTransform); ``collisions``: the station's ``CollisionProbe`` (its obstacles and the
    robot's bodies); ``body_of_geometry``: GeometryId → body index (hydroelastic contacts)."""

    def __init__(self, parts, belts, left: int, right: int, robot, tool, collisions: CollisionProbe,
                 body_of_geometry: dict):
        super().__init__()
        self._parts = [int(b) for b in parts]
        self._part_slot = {b: k for k, b in enumerate(self._parts)}
        self._belts = {int(b) for b in belts}
        self._left, self._right = int(left), int(right)
        self._pads = {self._left: 0, self._right: 1}
        self._robot = {int(b) for b in robot}
        self._tool_body, self._X_BT = int(tool[0]), tool[1]
        self._obstacle, self._fingers = collisions.obstacle_of, collisions.fingers
        self._collision_robot = collisions.robot
        self._geometry = body_of_geometry
        self._contacts = self.DeclareAbstractInputPort("contact_results",
                                                       AbstractValue.Make(ContactResults()))
        self._poses = self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        n, m = PART_WIDTH * len(self._parts) + 8, 2 * len(self._parts)
        self.blocks = {"probe": slice(0, n), "grip_forces": slice(n, n + m),
                       "collisions": slice(n + m, n + m + collisions.num_flags)}
        self._size = n + m + collisions.num_flags
        self.DeclareVectorOutputPort("values", self._size, self._calc, {self.all_input_ports_ticket()})

    def _calc(self, context, output) -> None:
        """[probe; grip_forces; collisions] (module docstring), the contacts and poses read once."""
        n = self.blocks["probe"].stop
        collided = self.blocks["collisions"].start
        out = np.zeros(self._size)
        poses = self._poses.Eval(context)
        for k, body in enumerate(self._parts):
            X = poses[body]
            out[PART_WIDTH * k: PART_WIDTH * k + 3] = X.translation()
            out[PART_WIDTH * k + 3: PART_WIDTH * k + 7] = X.rotation().ToQuaternion().wxyz()
        X_WT = poses[self._tool_body] @ self._X_BT
        R_WT = X_WT.rotation()
        out[n - 7:n - 4], out[n - 4:n] = X_WT.translation(), R_WT.ToQuaternion().wxyz()
        x_tool = None
        slot, pads, robot, belts = self._part_slot, self._pads, self._robot, self._belts
        obstacle, fingers, collision_robot = self._obstacle, self._fingers, self._collision_robot
        results = self._contacts.Eval(context)
        info = results.point_pair_contact_info
        count = results.num_point_pair_contacts()
        for i in range(count + results.num_hydroelastic_contacts()):
            if i < count:  # a point pair: its record holds the bodies and the force
                c = info(i)
                a, b = int(c.bodyA_index()), int(c.bodyB_index())
            else:  # a hydroelastic contact (``contact_pairs.contact_pairs``'s order and bodies)
                c = None
                surface = results.hydroelastic_contact_info(i - count).contact_surface()
                a, b = self._geometry[surface.id_M()], self._geometry[surface.id_N()]
            # the collision flags (``CollisionProbe``)
            ca, cb = (b, a) if b in collision_robot else (a, b)
            if ca in collision_robot and cb in obstacle:
                out[collided + 2 * obstacle[cb] + (FINGER if ca in fingers else OBSTACLE_OTHER)] = 1.0
            # the parts' contact flags, the pads' forces and the belt flag
            if b in slot and a in robot:
                a, b = b, a
            if a in slot and b in robot:
                k = slot[a]
                pad = pads.get(b)
                out[PART_WIDTH * k + (OTHER if pad is None else LEFT + pad)] = 1.0
                if pad is not None:  # a pad on a part: its force along the closing axis
                    if x_tool is None:
                        x_tool = np.array(R_WT.matrix()[:, 0])  # a copy while R_WT lives (Drake 1.51's views)
                    where = count - 1 - i  # (a hydroelastic contact's place: ``contact_force``)
                    f = contact_force(results, where) if c is None else np.array(c.contact_force())
                    out[n + 2 * k + pad] += abs(float(np.dot(f, x_tool)))
            elif (a in robot and b in belts) or (b in robot and a in belts):
                out[n + BELT] = 1.0
        output.SetFromVector(out)
