"""Before a pick run: is every segment's tf long enough for the arm's joints?

The feasibility model of ``run_warnings`` (``joint_demand``: the joint speeds |J⁺ẋ| against the
model's velocity limits and the torques of the inverse dynamics against its effort limits) is
evaluated along the whole planned profile of every segment of the run's plan, vias included: the
way ``ways.nominal_paths`` follows (each segment's target — the part riding its belt at its
nominal speed, the latched lift point, a slot, a via — and the error dynamics e(t) = ξ(t) e(t0)
from where the previous segment's target was), sampled ``run_warnings.SPEED_SAMPLES`` times, so
the time base generator's peak speed (ξ̇, at mid-segment) and acceleration (ξ̈; β < 1/2 is taken
as 1/2, where ξ̈ is unbounded) are both in it.  The tool turns from its yaw at the segment's start
to the target's top-down branch (``route.tool_yaws``) on the same ξ; the posture at each sample
comes from Drake's ``InverseKinematics`` (the top-down orientation, from the previous sample's
posture).  The first 5 % of each segment are left out (``run_warnings.PROFILE_START``: the ideal
profile starts at the target's velocity while the arm is at rest).  The task velocity is the 6-D
[ω; v], weighed and inverted as the controller does (``controller.rot_scale``, its damped
pseudoinverse with ``controller.pinv_damping``); the torques are those of the station's plant
(the arm with its gripper) plus, from the lift to the place, the part's mass held at the tool.

A planning estimate from the model (the controller never sees it): one warning line per segment
that asks a joint for more than its limit, naming the pick, the phase, the segment, the joint and
the ratio (``run_warnings.feasibility_warning``).  Measured on ``tests/two_belt_pick.yaml`` with
pick 1's approach cut to 0.3 s: docs/pick_place.md ("Checks before and during the run").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ptint_drake.robot.plant import effort_limits
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.verdict.run_warnings import (SPEED_SAMPLES, Profile, feasibility_warning, joint_demand,
                                               profile_times)
from ptint_drake.worlds.pick.route import tool_yaws
from ptint_drake.worlds.pick.ways import nominal, segment_target, start_error
from ptint_drake.worlds.pick.tasks import VIA_PART, VIA_SLOT

HELD = ("lift", "carry", "place")  # phases that carry the part (a via before a carry too)


@dataclass(frozen=True)
class Way:
    """One segment's way as the feasibility model follows it: its ``target`` at the segment's start
    (m) riding at ``ride`` (m/s; 0 for a fixed target), the start error ``e0`` = where the tool
    starts less that target (m), the tool's yaw at the start and at the target (rad, ``yaws``),
    and the ``payload`` (kg) held at the tool."""

    target: np.ndarray
    ride: np.ndarray
    e0: np.ndarray
    yaws: tuple = (0.0, 0.0)
    payload: float = 0.0


def top_down(yaw: float) -> np.ndarray:
    """Rz(yaw)·Rx(π): the top-down tool turned to ``yaw`` (rad)."""
    c, n = np.cos(yaw), np.sin(yaw)
    return np.array([[c, n, 0.0], [n, -c, 0.0], [0.0, 0.0, -1.0]])


def way_postures(arm, frame, way: Way, tf: float, beta: float, q: np.ndarray,
                 samples: int = SPEED_SAMPLES) -> Optional[np.ndarray]:
    """The postures (samples × nq) along ``way`` taken in ``tf`` s with TBG shape ``beta`` at the
    feasibility model's ``samples`` (``run_warnings.profile_times``), each by Drake's
    ``InverseKinematics`` from the previous one's (the first from ``q``); None where a sample has
    no top-down posture."""
    tau = profile_times(tf, samples)
    xi = tbg_profile(tau, tf, beta)[0]
    yaw0, yaw1 = way.yaws
    postures = []
    for k, t in enumerate(tau):
        x = way.target + way.ride * t + xi[k] * way.e0
        q = inverse_kinematics(arm, frame, x, q, R=top_down(yaw1 + xi[k] * (yaw0 - yaw1)))
        if q is None:
            return None
        postures.append(q)
    return np.array(postures)


def way_motion(way: Way, tf: float, beta: float,
               samples: int = SPEED_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """(velocity, acceleration) of the tool along ``way`` in ``tf`` s, [ω; v] and [α; a] per sample
    (``profile_times``): ẋ = ẋ_target + ξ̇ e0 and ẍ = ξ̈ e0, the yaw turning on the same ξ (β < 1/2
    taken as 1/2 for ξ̈, where it is unbounded)."""
    tau = profile_times(tf, samples)
    xi_d = tbg_profile(tau, tf, beta)[1]
    xi_dd = tbg_profile(tau, tf, max(beta, 0.5))[2]
    turn = way.yaws[0] - way.yaws[1]
    z = np.array([0.0, 0.0, 1.0])
    velocity = np.hstack([np.outer(xi_d * turn, z), way.ride + np.outer(xi_d, way.e0)])
    acceleration = np.hstack([np.outer(xi_dd * turn, z), np.outer(xi_dd, way.e0)])
    return velocity, acceleration


def way_profile(arm, frame, way: Way, tf: float, beta: float, q: np.ndarray,
                start: float = 0.0) -> Optional[Profile]:
    """The ``run_warnings.Profile`` of ``way`` taken in ``tf`` s from time ``start`` (module
    docstring): the one evaluation the warnings before a run and ``phase_time.min_tf`` share."""
    postures = way_postures(arm, frame, way, tf, beta, q)
    if postures is None:
        return None
    velocity, acceleration = way_motion(way, tf, beta)
    return Profile(start + profile_times(tf), postures, velocity, acceleration, way.payload)


def _profiles(scenario, built) -> list:
    """Per segment of the run's plan: its ``run_warnings.Profile`` (module docstring); None for a
    segment with a sample that has no top-down posture (``check_pick_reachable`` names those)."""
    arm, plan = built.arm, built.plan
    world = nominal(scenario, arm)
    frame = arm.GetFrameByName(scenario.robot.end_effector)
    names = [p.name for p in scenario.pick.parts]
    masses = [p.mass for p in scenario.pick.parts]
    yaws = tool_yaws(world, plan)
    q, out = world.q0, []
    for i, (seg, s) in enumerate(zip(plan.segments, plan.schedule.segments)):
        ride = world.parts[seg.index][1] if seg.kind == "part" else np.asarray(seg.ride, float)
        task = scenario.pick.tasks[seg.task]
        held = seg.phase in HELD or seg.kind == VIA_SLOT
        payload = masses[names.index(task.part)] if held else 0.0
        way = Way(segment_target(world, plan, i, s.start)[0], ride, start_error(world, plan, i), yaws[i],
                  payload)
        profile = way_profile(arm, frame, way, s.tf, s.beta, q, s.start)
        if profile is not None:
            q = profile.q[-1]
        out.append(profile)
    return out


def feasibility_warnings(scenario, built) -> list[str]:
    """One line per segment of the pick's plan whose tf is too short for a joint's speed or effort
    limit along its planned profile (module docstring); [] when every segment fits."""
    station, plan = built.station, built.plan
    plant = station.plant
    frame = plant.GetFrameByName(scenario.robot.end_effector, station.arm)
    nv = plant.num_velocities()
    cols = plant.GetVelocitiesFromArray(station.arm, np.arange(nv, dtype=float)).astype(int)
    speed_limits = plant.GetVelocityUpperLimits()[cols]
    efforts = effort_limits(built.arm)
    out = []
    for i, profile in enumerate(_profiles(scenario, built)):
        if profile is None:
            continue
        seg = plan.segments[i]
        speeds, torques = joint_demand(plant, frame, profile, station.arm, scenario.controller.rot_scale,
                                       scenario.controller.pinv_damping)
        phase = seg.phase if seg.phase != "via" else ("approach" if seg.kind == VIA_PART else "carry")
        field = f"pick.tasks[{seg.task}].{phase}.tf"
        what = f"pick {seg.task}'s {seg.phase} (segment {i})"
        tf = getattr(scenario.pick.tasks[seg.task], phase).tf  # the field's (a via shares its phase's)
        warning = feasibility_warning(field, tf, what, profile, speeds, torques, speed_limits, efforts)
        if warning:
            out.append(warning)
    return out
