"""``CollisionProbe`` — which obstacle the arm or its gripper touches, read from the plant's
contact results (the simulation's truth, for the metrics; a controller never sees it) through
``contact_pairs.ContactPairs`` (the bodies of each contact, read once for this probe and the
run's ``PickProbe``).

An *obstacle* is every body the robot must not touch: each belt, the tray, the floor (the world
body's geometry) and each part — a part only counts when it is not the one being grasped (the
fingers may touch that one, nothing else of the robot may).  Per obstacle two flags (1 or 0): in
contact with a finger (pad or stem), in contact with any other body of the arm or the gripper.

==================  ===========  ======================================================
port                size         meaning
==================  ===========  ======================================================
``contact_pairs``   —            input: (body A, body B, where) per contact (``ContactPairs``)
``collisions``      2 · n        output: per obstacle [finger contact, other robot contact]
==================  ===========  ======================================================

``collision_bodies`` reads the logged flags for one pick: the obstacles touched within the
task's window (from its start, or t = 0 for the first task, until the next task starts or the
run ends), the task's own part excepted from its fingers' contacts.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem

FINGER, OTHER = 0, 1  # the flags' places in an obstacle's pair


class CollisionProbe(LeafSystem):
    """Contact flags per obstacle (module docstring).  ``obstacles``: the obstacles' body index
    lists (a belt, the tray, the world body for the floor, a part), in output order;
    ``fingers``, ``robot``: body indices of the fingers and of every arm and gripper body."""

    def __init__(self, obstacles: list, fingers, robot):
        super().__init__()
        # what the flags are made of (read by ``probe.PickProbe``, which records the same flags)
        self.obstacle_of = {int(b): k for k, bodies in enumerate(obstacles) for b in bodies}
        self.fingers = frozenset(int(b) for b in fingers)
        self.robot = frozenset(int(b) for b in robot)
        self.num_flags = 2 * len(obstacles)
        self._pairs = self.DeclareAbstractInputPort("contact_pairs", AbstractValue.Make(()))
        self.DeclareVectorOutputPort("collisions", self.num_flags, self._calc)

    def _calc(self, context, output) -> None:
        out = np.zeros(output.size())
        for a, b, _ in self._pairs.Eval(context):
            if b in self.robot:
                a, b = b, a
            if a in self.robot and b in self.obstacle_of:
                out[2 * self.obstacle_of[b] + (FINGER if a in self.fingers else OTHER)] = 1.0
        output.SetFromVector(out)


def collision_bodies(names: list, t: np.ndarray, flags: np.ndarray, window: tuple, own: str) -> list:
    """The obstacles (names, output order) touched by the robot for t in ``window`` = (start,
    end), from the logged ``flags`` (rows: CollisionProbe outputs at times ``t``); the part named
    ``own`` (the one being picked) only counts when something other than a finger touches it."""
    inside = (t >= window[0]) & (t < window[1])
    touched = []
    for k, name in enumerate(names):
        columns = [2 * k + OTHER] if name == own else [2 * k + FINGER, 2 * k + OTHER]
        if np.any(flags[np.ix_(inside, columns)] > 0):
            touched.append(name)
    return touched


def pick_collisions(built, logs: dict, k: int) -> list:
    """``collision_bodies`` of task k of a built pick run (``run.PickBuilt``) from its ``logs``
    (``"collisions"``: the station's port logged): its window runs from its start (its first
    approach's, or that of the via before it; 0 for the first task) to the next task's start (the
    run's end for the last)."""
    if "collisions" not in logs:
        return []
    t, flags = logs["collisions"]
    plan = built.plan
    window = task_window(plan, k)
    own = built.station.config.parts[plan.segments[plan.segment_index(k, "approach")].index].name
    return collision_bodies(built.station.obstacles, t, flags, window, own)


def task_window(plan, k: int) -> tuple:
    """(start, end) of task k's window in a ``tasks.PickPlan``: from its first approach's start (or
    that of the via before it; 0 for the first task) to the next task's (``inf`` for the last)."""
    starts = [plan.attempts[j][0].start for j in range(len(plan.close_times))]  # (a via's start, if any)
    return (0.0 if k == 0 else starts[k], starts[k + 1] if k + 1 < len(starts) else np.inf)


def touched_before_close(built, logs: dict, mask: np.ndarray) -> list:
    """The obstacles (names, the station's order) the arm or the gripper touched at the samples
    ``mask`` of the logged ``collisions`` — every body, the task's own part included and touched by
    the fingers too: ``mask`` is a task's approaches and descends before their close commands,
    where the open fingers must touch nothing (the metrics' ``collision``)."""
    if "collisions" not in logs:
        return []
    flags = logs["collisions"][1][mask]
    return [name for k, name in enumerate(built.station.obstacles)
            if np.any(flags[:, [2 * k + FINGER, 2 * k + OTHER]] > 0)]
