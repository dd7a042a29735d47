"""The one tracer of a pick plan's ways: where each segment's target is, nominally, and the way the
tool takes to it.

A prescribed-time segment follows its error dynamics e(t) = ξ(t) e(t0) (SPEC 2.1, ξ the time base
generator): towards a fixed target (a slot, a via, a latched lift point) a straight line, towards a
part riding its belt a straight line relative to the part.  ``nominal`` gathers what the plan is
made against — per part its nominal centre at t = 0 and its belt's velocity, per task the place
pose, the start posture's tool point, the waist axis and the arm's kinematics: configuration and
the arm's model only, never the simulated world — and ``segment_way`` samples a segment's way from
where the previous segment's target is at its start.  The vias (``route``), the checks before the
run (``clearance``, ``feasibility``, ``singularity``) and the obstacle check (``obstacles``) all
follow it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.multibody.tree import JointIndex
from scipy.special import betaincinv

from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.worlds.pick.camera import nominal_paths as nominal_motions
from ptint_drake.worlds.pick.placement import nominal_parts
from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.tasks import PLACES, VIA_PART, VIA_SLOT, PickPlan, place_target

SAMPLES = 41  # samples of each segment's way


def xi(tau: np.ndarray, tf: float, beta: float) -> np.ndarray:
    """ξ(τ) = I⁻¹(1−β, 1−β; 1 − τ/tf): the share of a segment's initial error left at τ."""
    return betaincinv(1.0 - beta, 1.0 - beta, np.clip(1.0 - tau / tf, 0.0, 1.0))


@dataclass
class Nominal:
    """What the plan is made against: per part its nominal centre at t = 0 and its belt's velocity,
    per segment of ``plan`` the place pose of a "slot" segment (None otherwise), the start
    posture's tool point, the waist axis (x, y) and the arm's kinematics."""

    parts: list
    part_yaws: list
    places: list
    start: np.ndarray
    axis: np.ndarray
    arm: object
    frame: object
    q0: np.ndarray


def waist_axis(arm) -> np.ndarray:
    """(x, y) of the arm's first revolute joint axis (its waist), in the world."""
    context = arm.CreateDefaultContext()
    for i in range(arm.num_joints()):
        joint = arm.get_joint(JointIndex(i))
        if joint.num_velocities() == 1 and "revolute" in joint.type_name():
            return joint.frame_on_child().CalcPoseInWorld(context).translation()[:2]
    return np.zeros(2)


def nominal(scenario, arm) -> Nominal:
    """The ``Nominal`` of a pick scenario (configuration and the arm's model only)."""
    pick = scenario.pick
    parts = nominal_motions(pick)
    yaws = [float(np.radians(part.yaw_deg)) for part in nominal_parts(pick.parts)]
    names = [p.name for p in pick.parts]
    places = []
    for task in pick.tasks:
        kind, index, _ = place_target(pick, task)
        places.append(place_point(pick, kind, index, pick.parts[names.index(task.part)], task.belt_at))
    frame = arm.GetFrameByName(scenario.robot.end_effector)
    context = arm.CreateDefaultContext()
    q0 = np.radians(scenario.robot.initial_q_deg)
    arm.SetPositions(context, q0)
    start = frame.CalcPoseInWorld(context).translation()
    return Nominal(parts, yaws, places, start, waist_axis(arm), arm, frame, q0)


def segment_target(world: Nominal, plan: PickPlan, i: int, t) -> np.ndarray:
    """Where segment i aims at time(s) t (rows), nominally."""
    seg, s = plan.segments[i], plan.schedule.segments[i]
    t = np.atleast_1d(np.asarray(t, float))
    offset = np.asarray(seg.offset, float)
    if seg.kind in (VIA_PART, VIA_SLOT):
        return np.tile(offset, (len(t), 1))
    if seg.kind in PLACES:  # (an outgoing belt's place rides it: ``PlanSegment.ride``)
        return world.places[seg.task] + offset + np.outer(t, np.asarray(seg.ride, float))
    p0, v = world.parts[seg.index]
    if seg.kind == "latched":
        return np.tile(p0 + v * s.start + offset, (len(t), 1))
    return p0 + np.outer(t, v) + offset


def start_error(world: Nominal, plan: PickPlan, i: int) -> np.ndarray:
    """e(t0) of segment i (m): where the way starts — the previous segment's target at this one's
    start, the start posture's tool point for the first — less this segment's target then."""
    s = plan.schedule.segments[i]
    x0 = world.start if i == 0 else segment_target(world, plan, i - 1, s.start)[0]
    return x0 - segment_target(world, plan, i, s.start)[0]


def segment_way(world: Nominal, plan: PickPlan, i: int, tau: np.ndarray) -> np.ndarray:
    """Segment i's way at the times ``tau`` after its start (rows × 3, m): its target plus
    ξ(τ) e(t0), ideal tracking of the error dynamics (module docstring).  The one tracer of the
    planned way: the vias here, the clearance and the feasibility checks all follow it."""
    s = plan.schedule.segments[i]
    tau = np.asarray(tau, float)
    return (segment_target(world, plan, i, s.start + tau)
            + np.outer(xi(tau, s.tf, s.beta), start_error(world, plan, i)))


def nominal_paths(world: Nominal, plan: PickPlan, samples: int = SAMPLES) -> list:
    """Per segment of ``plan``: its way (``samples`` × 3, m) over the whole segment (``segment_way``)."""
    return [segment_way(world, plan, i, np.linspace(0.0, s.tf, samples))
            for i, s in enumerate(plan.schedule.segments)]


def down_posture(world: Nominal, x: np.ndarray, guess=None):
    """A top-down posture of the tool at ``x`` within the joint limits (Drake's
    ``InverseKinematics``, from ``guess`` or the start posture), or None."""
    return inverse_kinematics(world.arm, world.frame, x, world.q0 if guess is None else guess, down=True)
