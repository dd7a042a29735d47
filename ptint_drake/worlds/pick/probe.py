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

A recorder, read after the run, as Drake's ``VectorLogSink`` is: at each sample (every
``period``, and at forced publishes: a ``VectorLogSink``'s triggers, so its times are the other
loggers') it keeps the time, the plant's [q; v] and the plant's ``ContactResults`` (a copy that
shares the step's contact data: about 1–2 µs), in a per-context log (a cache entry that nothing
invalidates, as ``VectorLogSink`` keeps its log).  ``log(context)`` turns the samples into rows:
the poses by forward kinematics of the kept q on a context of the plant (the numbers
``body_poses`` gives), the flags and forces from the kept contacts.  Reading a ContactResults
from Python costs a binding call per contact and field (about 3 µs a contact on Drake 1.51's
bindings, a part resting on a belt alone making 5 point contacts): read in the loop it was
~0.07 s per simulated second of ``assembly_pick_place``, now paid once after the run.  A sample
with hydroelastic contacts is read at once (its flags and pad force vectors kept), since a copy
would keep every contact surface's mesh alive until the run ends; past ``MAX_COPIES`` kept copies
(20 s of samples, ~50 MB) the oldest are read during the run, ``READ_BATCH`` at a time, so a long
run's memory stays bounded (``copies_read``).

==================  ===========  ======================================================
port                size         meaning
==================  ===========  ======================================================
``contact_results`` —            input: the plant's ContactResults
``plant_state``     nq + nv      input: the plant's [q; v]
==================  ===========  ======================================================

``log(context)``: (times, rows), each row [probe (10·n + 8); grip_forces (2·n); collisions (2·m)].
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.multibody.plant import ContactResults
from pydrake.multibody.tree import BodyIndex
from pydrake.systems.framework import LeafSystem, ValueProducer

from ptint_drake.worlds.pick.collisions import FINGER, CollisionProbe
from ptint_drake.worlds.pick.collisions import OTHER as OBSTACLE_OTHER
from ptint_drake.worlds.pick.contact_pairs import contact_force

PART_WIDTH = 10  # values per part in the probe's output
LEFT, RIGHT, OTHER = 7, 8, 9  # the contact flags' places in a part's block
BELT = -8  # the belt flag's place; the tool's pose is the last 7 values


MAX_COPIES = 10_000  # kept ContactResults copies (20 s at 2 ms; ~5 kB each with 20 point contacts)
READ_BATCH = 1_000  # past MAX_COPIES, the oldest copies read at once


@dataclass
class _Samples:
    """A context's samples: (t, [q; v], a ContactResults copy or its reading) each; the copies
    start at ``first_copy`` (older ones were read in the run, ``PickProbe._record``)."""

    samples: list = field(default_factory=list)
    first_copy: int = 0


class PickProbe(LeafSystem):
    """Part poses, contact flags, pad forces and collision flags, recorded (module docstring).
    ``plant``: the station's plant; ``parts``, ``belts``: body indices in config order; ``left``,
    ``right``: the pads' bodies; ``robot``: every arm and gripper body; ``tool``: the tool frame's
    body index and its pose in that body (RigidTransform); ``collisions``: the station's
    ``CollisionProbe`` (its obstacles and the robot's bodies); ``body_of_geometry``: GeometryId →
    body index (hydroelastic contacts); ``period``: between samples (s)."""

    def __init__(self, plant, parts, belts, left: int, right: int, robot, tool, collisions: CollisionProbe,
                 body_of_geometry: dict, period: float):
        super().__init__()
        self._plant = plant
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
        self._state = self.DeclareVectorInputPort("plant_state", plant.num_multibody_states())
        n, m = PART_WIDTH * len(self._parts) + 8, 2 * len(self._parts)
        self.blocks = {"probe": slice(0, n), "grip_forces": slice(n, n + m),
                       "collisions": slice(n + m, n + m + collisions.num_flags)}
        self._size = n + m + collisions.num_flags
        bodies = (set(self._parts) | self._belts | self._robot | set(self._obstacle)
                  | set(self._collision_robot))
        self._table = {(a, b): act for a in bodies for b in bodies if (act := self._action(a, b))[0]}
        # the samples, per context (as VectorLogSink keeps its log: a cache entry nothing invalidates)
        keep = ValueProducer(allocate=lambda: AbstractValue.Make(_Samples()),
                             calc=lambda context, value: None)
        self._log = self.DeclareCacheEntry("samples", keep, {self.nothing_ticket()})
        self.max_copies = MAX_COPIES
        self.DeclarePeriodicPublishEvent(period, 0.0, self._record)
        self.DeclareForcedPublishEvent(self._record)

    def _action(self, a: int, b: int) -> tuple:
        """What a contact between bodies ``a`` and ``b`` (in this order) sets: the row's places
        of its flags (a collision, a part's pad or other-robot contact, the belt flag) and the
        place of the pad force it adds to (−1: none) — the module docstring's rules, decided once
        per pair of bodies in ``__init__`` (``_table``) rather than per contact and sample."""
        n, collided = self.blocks["probe"].stop, self.blocks["collisions"].start
        flags, force = [], -1
        ca, cb = (b, a) if b in self._collision_robot else (a, b)
        if ca in self._collision_robot and cb in self._obstacle:
            place = 2 * self._obstacle[cb] + (FINGER if ca in self._fingers else OBSTACLE_OTHER)
            flags.append(collided + place)
        if b in self._part_slot and a in self._robot:
            a, b = b, a
        if a in self._part_slot and b in self._robot:
            k, pad = self._part_slot[a], self._pads.get(b)
            flags.append(PART_WIDTH * k + (OTHER if pad is None else LEFT + pad))
            if pad is not None:
                force = n + 2 * k + pad
        elif (a in self._robot and b in self._belts) or (b in self._robot and a in self._belts):
            flags.append(n + BELT)
        return tuple(flags), force

    def _samples(self, context) -> _Samples:
        return self._log.get_mutable_cache_entry_value(context).GetMutableValueOrThrow()

    def copies_read(self, context) -> int:
        """How many of the samples kept in ``context`` were read during the run (``max_copies``)."""
        return self._samples(context).first_copy

    def _record(self, context) -> None:
        """Keep this instant: its time, the plant's [q; v] and its contacts (module docstring);
        past ``max_copies`` kept copies, read the oldest ``READ_BATCH`` now (bounded memory)."""
        results = self._contacts.Eval(context)
        contacts = self._read(results) if results.num_hydroelastic_contacts() else copy.copy(results)
        log = self._samples(context)
        log.samples.append((context.get_time(), self._state.Eval(context).copy(), contacts))
        if len(log.samples) - log.first_copy > self.max_copies:
            batch = min(READ_BATCH, self.max_copies)
            for i in range(log.first_copy, log.first_copy + batch):
                t, x, kept = log.samples[i]
                if isinstance(kept, ContactResults):  # (a hydroelastic sample was read when kept)
                    log.samples[i] = (t, x, self._read(kept))
            log.first_copy += batch

    def _read(self, results: ContactResults) -> tuple:
        """(the row's places each contact sets to 1, (place, force vector) of each pad on a
        part) of ``results``, in the contacts' order (``contact_pairs``')."""
        action = self._table.get
        flags, forces = [], []
        info = results.point_pair_contact_info
        for i in range(results.num_point_pair_contacts()):  # a point pair: bodies and force in one record
            c = info(i)
            act = action((int(c.bodyA_index()), int(c.bodyB_index())))
            if act is not None:
                flags += act[0]
                if act[1] >= 0:
                    forces.append((act[1], np.array(c.contact_force())))
        geometry = self._geometry
        for j in range(results.num_hydroelastic_contacts()):
            surface = results.hydroelastic_contact_info(j).contact_surface()
            act = action((geometry[surface.id_M()], geometry[surface.id_N()]))
            if act is not None:
                flags += act[0]
                if act[1] >= 0:
                    forces.append((act[1], contact_force(results, -1 - j)))
        return flags, forces

    def log(self, context) -> tuple[np.ndarray, np.ndarray]:
        """(times, rows) of the samples kept in ``context`` (module docstring)."""
        samples = self._samples(context).samples
        plant, n = self._plant, self.blocks["probe"].stop
        plant_context = plant.CreateDefaultContext()
        parts = [plant.get_body(BodyIndex(b)) for b in self._parts]
        tool = plant.get_body(BodyIndex(self._tool_body))
        nq = plant.num_positions()
        rows = np.zeros((len(samples), self._size))
        for row, (_, x, contacts) in zip(rows, samples):
            plant.SetPositions(plant_context, x[:nq])
            for k, body in enumerate(parts):
                X = plant.EvalBodyPoseInWorld(plant_context, body)
                row[PART_WIDTH * k: PART_WIDTH * k + 3] = X.translation()
                row[PART_WIDTH * k + 3: PART_WIDTH * k + 7] = X.rotation().ToQuaternion().wxyz()
            X_WT = plant.EvalBodyPoseInWorld(plant_context, tool) @ self._X_BT
            R_WT = X_WT.rotation()
            row[n - 7:n - 4], row[n - 4:n] = X_WT.translation(), R_WT.ToQuaternion().wxyz()
            flags, forces = self._read(contacts) if isinstance(contacts, ContactResults) else contacts
            if flags:
                row[flags] = 1.0
            if forces:  # a pad's force along the closing axis, summed in the contacts' order
                x_tool = np.array(R_WT.matrix()[:, 0])  # a copy while R_WT lives (Drake 1.51's views)
                sums: dict = {}
                for place, f in forces:
                    sums[place] = sums.get(place, 0.0) + abs(float(np.dot(f, x_tool)))
                row[list(sums)] = list(sums.values())
        return np.array([t for t, _, _ in samples]), rows
