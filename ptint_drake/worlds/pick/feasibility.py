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

import numpy as np

from ptint_drake.robot.plant import effort_limits
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.task.tbg import tbg_profile
from ptint_drake.verdict.run_warnings import Profile, feasibility_warning, joint_demand, profile_times
from ptint_drake.worlds.pick.route import tool_yaws
from ptint_drake.worlds.pick.ways import nominal, segment_target, start_error
from ptint_drake.worlds.pick.tasks import VIA_PART, VIA_SLOT

HELD = ("lift", "carry", "place")  # phases that carry the part (a via before a carry too)


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
        tau = profile_times(s.tf)
        target = segment_target(world, plan, i, s.start + tau)
        ride = world.parts[seg.index][1] if seg.kind in ("part",) else np.zeros(3)
        xi, xi_d = tbg_profile(tau, s.tf, s.beta)[0:2]
        xi_dd = tbg_profile(tau, s.tf, max(s.beta, 0.5))[2]
        e0 = start_error(world, plan, i)
        yaw0, yaw1 = yaws[i]
        turn = yaw0 - yaw1
        postures = []
        for k in range(len(tau)):
            yaw = yaw1 + xi[k] * turn
            c, n = np.cos(yaw), np.sin(yaw)
            R = np.array([[c, n, 0.0], [n, -c, 0.0], [0.0, 0.0, -1.0]])  # Rz(yaw)·Rx(π): top-down
            solution = inverse_kinematics(arm, frame, target[k] + xi[k] * e0, q, R=R)
            if solution is None:
                break
            postures.append(solution)
            q = solution
        if len(postures) < len(tau):
            out.append(None)
            continue
        z = np.array([0.0, 0.0, 1.0])
        velocity = np.hstack([np.outer(xi_d * turn, z), ride + np.outer(xi_d, e0)])
        acceleration = np.hstack([np.outer(xi_dd * turn, z), np.outer(xi_dd, e0)])
        task = scenario.pick.tasks[seg.task]
        held = seg.phase in HELD or seg.kind == VIA_SLOT
        payload = masses[names.index(task.part)] if held else 0.0
        out.append(Profile(s.start + tau, np.array(postures), velocity, acceleration, payload))
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
