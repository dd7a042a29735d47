"""What the interceptor aims at during a pick and place, and when the fingers close and open.

``PickTargets`` — the target of the active segment of a ``pick.tasks.PickPlan``, in the layout of
the station's ``target`` and ``target_rotation`` ports, so any controller of the slot chases it:

=====================  ====  ================================================================
port                   size  meaning
=====================  ====  ================================================================
``part_k_pose``        9     input: part k's simulated [x, ẋ, ẍ] (``pick.part_pose``)
``part_k_rotation``    15    input: part k's [R, ω, ω̇]
``target``             9     output: [x_r, ẋ_r, ẍ_r] of the active segment (m, m/s, m/s²)
``target_rotation``    15    output: [R_r, ω_r, ω̇_r] of the active segment
=====================  ====  ================================================================

A "part" segment aims at the part's simulated centre + offset, with its velocity; ẍ_r and ω̇_r
are set to 0: a belt runs at constant speed, and the discrete plant's one-step accelerations are
contact chatter, not motion.  From a task's prescribed grasp time on (the descend's hold: the
part is in the hand) it aims at the part's motion as it was then, extrapolated at that velocity —
a target read off a part in the hand would follow the hand and hold nothing.  The velocity is the
part's at the task's close command (discrete state ``closing`` = [v, t]), before the fingers
touch it: a close that comes early (``close_delay`` < 0) grips the part before the prescribed
time, and the part's velocity then is the hand's, whatever the grip's squeeze jerked it to —
extrapolated, a runaway (measured, a harsh line sample: a close 54 ms early, the hand at 0.6 m/s
across the belt at the grasp time, the target carried 0.11 m off it and the arm into the belt).
A "latched" segment aims at where the part was at the segment's start + offset, at rest.
Discrete state ``latched`` = [p, v, t₀, R] (m, m/s, s, row-major), updated at each "latched"
segment's start and at each grasp time.  A "slot" segment aims at the fixed place pose, turned
to the slot's yaw about the vertical; a "bin" segment at the bin's drop point, turned as the part
was at the lift's start (the latched rotation: the tool keeps the yaw it grasped at); a "belt"
segment at its place point riding the outgoing belt (``PlanSegment.ride``, with that velocity)
until the segment's end, then at rest there (the last task's retreat stays active after it: a
target riding on would carry the arm out of reach), turned to the segment's yaw.  A via
segment (``pick.route``: the way around the arm's base) aims at its fixed point, at rest, turned as the
segment after it will be: as its part (``via_part``, before an approach), or to a yaw
(``via_slot``, before a carry: the slot's, or halfway to it the other way round).
A task with a chosen grip (``PlanSegment.grip``: a line's decision, ``line.cycle``) turns every
rotation read off its part — live, latched, or at a bin — about the vertical to the part's yaw by
its symmetry nearest the chosen yaw (``tasks.aimed_yaw``; a cylinder: the chosen yaw, its spin
about the vertical not followed), so the top-down task's branch, modulo π nearest the tool's yaw
(``orientation.top_down_of``), is the one the decision chose.

``GripperSequence`` — the gripper's opening command (m; 0 = close with the force limit) as a
function of time: the plan's commands, piecewise constant (output ``command``), and the width of
the part the active task grasps (output ``part_width``, m: what a grasp command of a real gripper
carries, for ``systems.hand.gripper.GraspObserver``).
"""

from __future__ import annotations

import bisect
import math
from typing import Sequence

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.systems.framework import BasicVector, Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from ptint_drake.controllers import TargetView
from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.schedule import ONE_SHOT_PERIOD, DeclareSegmentStartEvents
from ptint_drake.worlds.pick.tasks import PLACES, VIA_PART, VIA_SLOT, PickPlan, aimed_yaw

PART, LATCHED, SLOT, VIA = 0, 1, 2, 3  # a segment's kind ("part", "latched", "slot", "via_*") in ``_aims``


class PickTargets(LeafSystem):
    """The active segment's target of a pick plan (module docstring).  ``places[i]`` is the world
    position of segment i's place pose for "slot" segments (None otherwise).

    Both outputs come from one cache entry, ``aim`` = [target; target_rotation] (24): the
    controller reads both at every step and the loggers both at their samples, so each
    (time, state, inputs) is computed once.  What depends on the segment alone (its kind, the
    offset, a slot's place and yaw) is made once per plan (``_aims``)."""

    def __init__(self, plan: PickPlan, num_parts: int, places: Sequence):
        super().__init__()
        self._plan, self.places = plan, list(places)
        self._poses = [self.DeclareVectorInputPort(f"part_{k}_pose", 9) for k in range(num_parts)]
        self._rotations = [self.DeclareVectorInputPort(f"part_{k}_rotation", 15) for k in range(num_parts)]
        self._latched = self.DeclareDiscreteState(BasicVector(np.zeros(16)))
        self._closing = self.DeclareDiscreteState(BasicVector(np.r_[np.zeros(3), -1.0]))
        DeclareSegmentStartEvents(self, plan.schedule, self._latch)
        for k, t in enumerate(plan.grasp_times):
            self.DeclarePeriodicUnrestrictedUpdateEvent(ONE_SHOT_PERIOD, t, self._grasp_latch(k))
        for k, t in enumerate(plan.close_times):
            if t < plan.grasp_times[k]:  # (a close after the grasp time: the velocity then is the belt's)
                self.DeclarePeriodicUnrestrictedUpdateEvent(ONE_SHOT_PERIOD, t, self._close_latch(k))
        self._starts = plan.schedule.starts
        self._aims = [self._segment_aim(i) for i in range(len(plan.segments))]
        self._aim = DeclareVectorCache(self, "target and target_rotation", 24, self._calc_aim,
                                       {self.time_ticket(), self.xd_ticket(), self.all_input_ports_ticket()})
        self.DeclareVectorOutputPort("target", 9, lambda c, o: o.SetFromVector(self._aim(c)[0:9]))
        self.DeclareVectorOutputPort("target_rotation", 15, lambda c, o: o.SetFromVector(self._aim(c)[9:24]))

    def _segment_aim(self, i: int) -> tuple:
        """Segment i's (kind, part, offset, slot position, slot rotation (row-major), the
        prescribed grasp time of a descend (None otherwise), its task's grip (``turned``))."""
        seg = self._plan.segments[i]
        offset = np.asarray(seg.offset)
        if seg.kind in PLACES:  # a bin's: no yaw of its own (None), the tool keeps the latched one
            R = RotationMatrix.MakeZRotation(seg.yaw).matrix().ravel() if seg.kind != "bin" else None
            # (an outgoing belt's place: its point at t = 0, riding at ``seg.ride`` until the segment's
            # end, then at rest — the last retreat's target must not ride on out of reach)
            ride = (np.asarray(seg.ride, float), self._plan.schedule.segments[i].end)
            return (SLOT, None, offset, np.asarray(self.places[i]) + offset, R, ride, seg.grip)
        if seg.kind in (VIA_PART, VIA_SLOT):  # a fixed point; turned as its part, or to a yaw
            return (VIA, seg.index if seg.kind == VIA_PART else None, offset, offset,
                    RotationMatrix.MakeZRotation(seg.yaw).matrix().ravel(), None, seg.grip)
        end = self._plan.schedule.segments[i].end if seg.phase == "descend" else None
        return (PART if seg.kind == "part" else LATCHED, seg.index, offset, None, None, end, seg.grip)

    def _active(self, context) -> int:
        return max(self._plan.schedule.active(context.get_time()), 0)

    def _latch(self, context, state) -> None:
        value = self.latch_value(context)
        if value is not None:
            state.get_mutable_discrete_state(self._latched).SetFromVector(value)

    def latch_value(self, context):
        """The ``latched`` state a "latched" segment starting now sets (None: not such a segment).
        A run resumed in a new diagram at such a segment's start (``world.PickRun.resume``) sets
        it before the first step, so that every system's start-of-segment update reads it."""
        seg = self._plan.segments[self._active(context)]
        if seg.kind != "latched":
            return None
        position = self._poses[seg.index].Eval(context)[0:3]
        R = self._rotations[seg.index].Eval(context)[0:9]
        return np.r_[position, 0.0, 0.0, 0.0, context.get_time(), R]

    def _task_part(self, task: int) -> int:
        return self._plan.segments[self._plan.segment_index(task, "approach")].index

    def _close_latch(self, task: int):
        """At task ``task``'s close command: its part's velocity then (module docstring)."""
        def update(context, state) -> None:
            t = context.get_time()
            if abs(t - self._plan.close_times[task]) > 1e-9:
                return  # a one-shot event: only its first occurrence
            v = self._poses[self._task_part(task)].Eval(context)[3:6]
            state.get_mutable_discrete_state(self._closing).SetFromVector(np.r_[v, t])
        return update

    def _grasp_latch(self, task: int):
        def update(context, state) -> None:
            if abs(context.get_time() - self._plan.grasp_times[task]) > 1e-9:
                return  # a one-shot event: only its first occurrence
            pose = self._poses[self._task_part(task)].Eval(context)
            R = self._rotations[self._task_part(task)].Eval(context)[0:9]
            closing = context.get_discrete_state(self._closing).get_value()
            v = closing[0:3] if abs(closing[3] - self._plan.close_times[task]) < 1e-9 else pose[3:6]
            state.get_mutable_discrete_state(self._latched).SetFromVector(
                np.r_[pose[0:3], v, context.get_time(), R])
        return update

    def _calc_aim(self, context) -> np.ndarray:
        """[target (9); target_rotation (15)] of the active segment (module docstring).  A descend
        past its prescribed time whose grasp has been latched (the part in the hand) aims at the
        latched motion."""
        t = context.get_time()
        i = max(bisect.bisect_right(self._starts, t) - 1, 0)  # the active segment (Schedule.active)
        kind, part, offset, place, R_slot, grasp, grip = self._aims[i]
        value = np.zeros(24)
        if kind == SLOT:  # (``grasp``: the place's velocity, an outgoing belt's, else 0, and its end)
            ride, end = grasp
            value[0:3] = place + ride * min(t, end)
            value[3:6] = ride if t < end else 0.0
            value[9:18] = (R_slot if R_slot is not None
                           else turned(context.get_discrete_state(self._latched).get_value()[7:16], grip))
            return value
        if kind == VIA:
            value[0:3] = place
            value[9:18] = R_slot if part is None else turned(self._rotations[part].Eval(context)[0:9], grip)
            return value
        latched = context.get_discrete_state(self._latched).get_value()
        if kind == LATCHED:
            value[0:3], value[9:18] = latched[0:3] + offset, turned(latched[7:16], grip)
        elif grasp is not None and abs(latched[6] - grasp) < 1e-9:  # holding
            value[0:3] = latched[0:3] + latched[3:6] * (t - latched[6]) + offset
            value[3:6], value[9:18] = latched[3:6], turned(latched[7:16], grip)
        else:
            pose = self._poses[part].Eval(context)
            value[0:3], value[3:6] = pose[0:3] + offset, pose[3:6]
            value[9:21] = self._rotations[part].Eval(context)[0:12]
            if grip:
                value[9:18] = turned(value[9:18], grip)
                if grip[1] <= 0.0:
                    value[20] = 0.0  # (any yaw: the part's spin about the vertical not followed)
        return value


def turned(rotation: np.ndarray, grip: tuple) -> np.ndarray:
    """A part's rotation (9, row-major) turned about the world's vertical so that its x axis's yaw
    is ``tasks.aimed_yaw`` of it (``grip``: ``PlanSegment.grip``; () leaves it as it is)."""
    if not grip:
        return rotation
    yaw = math.atan2(rotation[3], rotation[0])
    d = aimed_yaw(yaw, grip) - yaw
    c, s = math.cos(d), math.sin(d)
    R = np.reshape(rotation, (3, 3))
    return np.vstack([c * R[0] - s * R[1], s * R[0] + c * R[1], R[2]]).ravel()


def _zero_order_hold(pairs: Sequence) -> PiecewisePolynomial:
    """A piecewise-constant signal of time through ``pairs`` [(t, value)] (sorted by t, stable: of
    commands at one time the last holds from it): the value of the last pair with t_i ≤ t, the
    first before it, the last after it — Drake's zero-order hold, whose segment at a break is the
    one that starts there."""
    times, values = [], []
    for t, v in sorted(pairs, key=lambda c: c[0]):
        if times and float(t) == times[-1]:
            values[-1] = float(v)
            continue
        times.append(float(t)), values.append(float(v))
    times.append(times[-1] + 1.0), values.append(values[-1])  # the last value held on
    return PiecewisePolynomial.ZeroOrderHold(times, np.array([values]))


class GripperSequence(Diagram):
    """The plan's gripper commands as a piecewise-constant signal of time (module docstring): two
    Drake ``TrajectorySource``s of zero-order holds (``_zero_order_hold``), C++ at every step."""

    def __init__(self, commands: Sequence, widths: Sequence = ()):
        super().__init__()
        self._command = _zero_order_hold(commands)
        self._width = _zero_order_hold(widths or [(0.0, 0.0)])
        builder = DiagramBuilder()
        for name, trajectory in (("command", self._command), ("part_width", self._width)):
            source = builder.AddNamedSystem(name, TrajectorySource(trajectory))
            builder.ExportOutput(source.get_output_port(), name)
        builder.BuildInto(self)

    def opening(self, t: float) -> float:
        """The commanded opening at time t (m; 0: close)."""
        return float(self._command.value(t)[0, 0])

    def part_width(self, t: float) -> float:
        """The width of the part the active task grasps at time t (m)."""
        return float(self._width.value(t)[0, 0])


class PortTargets(TargetView):
    """The target as ports already in the diagram (``PickTargets``'s outputs)."""

    def __init__(self, target, rotation):  # noqa: D107  (no call of TargetView.__init__: no analytic view)
        self.analytic = None
        self._port, self._rotation_port = target, rotation
