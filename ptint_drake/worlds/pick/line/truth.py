"""The truth side of a line: parts parked until their release, put on their belt at it, taken off
when they run past its end; the belt drives' speed steps; the slabs kept under the parts.

- **Parking.**  A pool part waits at its parking pose (``parking_pose``: under the floor, on a
  grid ``PARK_SPACING`` apart, out of every view and touching nothing) with its floating joint
  locked (Drake's ``Joint.Lock``: the discrete solver holds it, no contact work; measured: a
  parked part moves 0 m over a run, ``tests/unit/test_line_truth.py``).
- **Release** (a stop at its time): the part is put on its belt at its ``offset`` (the release
  point, upstream of the reach) and ``lateral``, turned ``yaw_deg``, resting on the slab and
  moving with it (the belt's current speed), and unlocked.
- **Past the end**: a part on a belt whose centre is within ``END_MARGIN`` of the belt's downstream
  end is parked again (it passed unpicked: ``passed``), so nothing piles up on the floor.
- **Speed steps** (``line.speed_steps``): at a step's time the belt's drive (its
  ``ConstantVectorSource``'s value in the context) takes factor × the declared speed; a step at
  t = 0 is the belt's speed from the start (``start``: the slab set moving at it too; the robust
  study's drawn speed).  The controller side is not told: the declared ``pick.belts[*].speed`` it
  builds from is unchanged.
- **The slab** translates with the belt; over a long run it would leave its rail.  At every stop
  it is put back at its declared place (its joint's position to 0, its speed kept): the slab's top
  is a uniform plane, so the parts riding it feel nothing (measured in the same test: the part's
  velocity before and after within 1e-6 m/s).  Between two stops (at most ``RESET_PERIOD``, the
  line's own stops) it drifts at most speed × ``RESET_PERIOD`` — the slack its length must leave.

- **The line done** (``done``, ``run_end``): the run's duration is a cap (sized for the slowest
  belt); the line is done at a stop when no release is left after it and every released part is
  parked past its belt's end or at rest (``at_rest``: below ``REST_SPEED`` and ``REST_RATE``) off
  every belt — a part on a belt, even at rest on a stopped one, can still be picked.  With the arm
  holding (its plan over, no new task at the stop: ``PickRun``), the run ends ``SETTLE`` after the
  first stop that found it done, if it is done still then (else it goes on to the next stop that
  finds it done).  The metrics judge the end's poses, as at the cap: a placed part was at rest
  ``SETTLE`` before (measured, ``line_assembly`` seeds 0–5: the third part's last 0.1 mm of motion
  0.33–0.34 s before its retreat's end).

Parameters (the locks, the drives' values) are not part of the numeric state a replan carries
(``PickRun.resume``): ``restore`` sets them again in a new context.
"""

from __future__ import annotations

import numpy as np
from pydrake.math import RigidTransform

from ptint_drake.worlds.pick.scene import belt_frame, part_shape, part_start_pose

PARK_Z = -0.5  # m: under the floor slab (its bottom at -0.1 m)
PARK_SPACING = 0.1  # m
END_MARGIN = 0.05  # m, from the belt's downstream end (at its declared place)
RESET_PERIOD = 0.5  # s, the line's own stops (the slab's reset, parts past the end)
SETTLE = 0.2  # s, from the first stop that finds the line done to the run's end (``run_end``)
REST_SPEED = 1e-3  # m/s; a part resting in its slot creeps at ~3e-5 m/s, 2e-3 rad/s (line_assembly)
REST_RATE = 0.02  # rad/s


def at_rest(plant, pc, body) -> bool:
    """A free body's speed below ``REST_SPEED`` and its turn rate below ``REST_RATE``."""
    V = plant.EvalBodySpatialVelocityInWorld(pc, body)
    return bool(np.linalg.norm(V.translational()) < REST_SPEED and np.linalg.norm(V.rotational()) < REST_RATE)


def parking_pose(k: int) -> RigidTransform:
    """Where pool part k waits: a grid under the floor."""
    return RigidTransform([-1.5 + PARK_SPACING * (k % 30), -1.5 + PARK_SPACING * (k // 30), PARK_Z])


class LineTruth:
    """The truth side's acts on a station's context (module docstring).  ``releases``:
    ``arrivals.Release`` per pool part; ``steps``: ``SpeedStepConfig`` list."""

    def __init__(self, station, releases: list, steps: list):
        self.station, self.releases, self.steps = station, releases, sorted(steps, key=lambda s: s.t)
        self.released = {}  # part → its release time (s)
        self.passed = {}  # part → when it was taken off past its belt's end (s)
        self.factors = {b.name: 1.0 for b in station.config.belts}
        self.done_since = None  # the first stop of the run's end (``run_end``)

    def rebind(self, station) -> None:
        """The new station of a rebuilt diagram (same configuration)."""
        self.station = station

    def stops(self, duration: float) -> list[float]:
        times = {r.t for r in self.releases} | {s.t for s in self.steps}
        times |= set(np.arange(RESET_PERIOD, duration, RESET_PERIOD).round(9))
        return sorted(t for t in times if 0.0 < t <= duration)

    def _joint(self, k: int):
        plant, body = self.station.plant, self.station.parts[k]
        (index,) = plant.GetJointIndices(body.model_instance())
        return plant.get_joint(index)

    def start(self, context) -> None:
        """At t = 0: every part parked (a release at 0 is done at its stop); the steps at 0 taken,
        every slab moving at its drive's speed."""
        pc = self.station.plant.GetMyMutableContextFromRoot(context)
        for k in range(len(self.station.parts)):
            self._park(pc, k)
        for step in self.steps:
            if step.t <= 0.0:
                self.factors[step.belt] = step.factor
        self._drive(context)
        for joint, belt in zip(self.station.belts, self.station.config.belts):
            joint.set_translation_rate(pc, self.factors[belt.name] * belt.speed)

    def _park(self, pc, k: int) -> None:
        plant, body = self.station.plant, self.station.parts[k]
        plant.SetFreeBodyPose(pc, body, parking_pose(k))
        plant.SetVelocities(pc, body.model_instance(), np.zeros(6))
        self._joint(k).Lock(pc)

    def at_stop(self, context, t: float) -> None:
        """The releases, steps, parts past the end and slab resets due at ``t``."""
        station, plant = self.station, self.station.plant
        pc = plant.GetMyMutableContextFromRoot(context)
        for step in self.steps:
            if abs(step.t - t) < 1e-9:
                self.factors[step.belt] = step.factor
        self._drive(context)
        belts = {b.name: b for b in station.config.belts}
        joints = {b.name: j for b, j in zip(station.config.belts, station.belts)}
        for r in self.releases:
            if abs(r.t - t) < 1e-9 and r.part not in self.released:
                self._release(pc, r.part, belts[r.belt], joints[r.belt])
                self.released[r.part] = t
        for k in self.released:
            if k not in self.passed and self._past_end(pc, k, belts):
                self._park(pc, k)
                self.passed[k] = t
        for joint in station.belts:
            joint.set_translation(pc, 0.0)

    def on_belt(self, pc, k: int) -> bool:
        """Part k's centre over a belt's top (any belt), within its largest size above it."""
        p = self.station.plant.EvalBodyPoseInWorld(pc, self.station.parts[k]).translation()
        reach = max(self.station.config.parts[k].size)
        for belt in self.station.config.belts:
            local = belt_frame(belt).inverse().multiply(p)
            if abs(local[0]) <= belt.length / 2 and abs(local[1]) <= belt.width / 2 + reach / 2 \
                    and 0.0 < local[2] < reach + 0.01:
                return True
        return False

    def done(self, context, t: float) -> bool:
        """The line done at ``t`` (module docstring): no release after it, every released part
        parked or at rest off the belts."""
        if len(self.released) < len(self.releases):
            return False
        plant, pc = self.station.plant, self.station.plant.GetMyContextFromRoot(context)
        for k in self.released:
            if k in self.passed:
                continue
            if not at_rest(plant, pc, self.station.parts[k]) or self.on_belt(pc, k):
                return False
        return True

    def run_end(self, context, t: float, rebuilt: bool, plan_end: float, cap: float) -> float:
        """The run's end as known at the stop ``t`` (module docstring): ``SETTLE`` after the first
        stop that found the line done with the arm free — no new plan at ``t`` (``rebuilt``), its
        plan over (``plan_end``, s) — while it stays so; else ``cap`` (s)."""
        if rebuilt or t < plan_end - 1e-9 or not self.done(context, t):
            self.done_since = None
            return cap
        if self.done_since is None:
            self.done_since = t
        return min(cap, self.done_since + SETTLE)

    def _release(self, pc, k: int, belt, joint) -> None:
        plant, body = self.station.plant, self.station.parts[k]
        part = self.station.config.parts[k]
        self._joint(k).Unlock(pc)
        plant.SetFreeBodyPose(pc, body, part_start_pose(part, belt))
        v = joint.get_translation_rate(pc) * np.asarray(belt.direction, dtype=float)
        plant.SetVelocities(pc, body.model_instance(), np.concatenate([np.zeros(3), v]))

    def _past_end(self, pc, k: int, belts: dict) -> bool:
        part = self.station.config.parts[k]
        belt = belts[part.belt]
        p = self.station.plant.EvalBodyPoseInWorld(pc, self.station.parts[k]).translation()
        local = belt_frame(belt).inverse().multiply(p)
        on = abs(local[1]) <= belt.width / 2 and abs(local[2] - part_shape(part)[1] / 2) < 0.01
        return bool(on and local[0] > belt.length / 2 - END_MARGIN)

    def _drive(self, context) -> None:
        for belt in self.station.config.belts:
            source = self.station.diagram.GetSubsystemByName(f"{belt.name}_speed")
            sc = source.GetMyMutableContextFromRoot(context)
            source.get_mutable_source_value(sc).SetFromVector([0.0, self.factors[belt.name] * belt.speed])

    def restore(self, context) -> None:
        """In a rebuilt diagram's context: the parked parts locked again, the drives' speeds."""
        pc = self.station.plant.GetMyMutableContextFromRoot(context)
        for k in range(len(self.station.parts)):
            if k not in self.released or k in self.passed:
                self._joint(k).Lock(pc)
        self._drive(context)

    def part_under(self, context, position) -> int:
        """The released part (not taken off) whose centre is nearest ``position`` (m, world): the
        pool part a camera track's task picks, by the truth — the metrics' name for the task (its
        targets read the track, never this); none on the line (a track of nothing): of all."""
        pc = self.station.plant.GetMyContextFromRoot(context)
        live = [k for k in self.released if k not in self.passed] or list(range(len(self.station.parts)))
        far = [np.linalg.norm(self.station.plant.EvalBodyPoseInWorld(pc, self.station.parts[k]).translation()
                              - np.asarray(position)) for k in live]
        return live[int(np.argmin(far))]

    def in_view(self, k: int) -> bool:
        """Part k is on the line now (released, not taken off)."""
        return k in self.released and k not in self.passed


