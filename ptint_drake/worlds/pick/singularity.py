"""Before a pick run: does the arm's path pass a singularity?

With as many joints as the task has dimensions (``rvm1_6dof`` on the 6-D ``top_down`` task) there
is no null space to go around a singularity: the roll-pitch-roll wrist of ``rvm1_6dof`` is
singular at wrist pitch 0, where its two roll axes line up, and an undamped J⁺ answers a small
orientation error there with large, opposite roll rates (issue 33: the forearm roll ran to −180°).
``singularity_warnings`` follows the pick's waypoints — the start posture, then per task the
pre-grasp, grasp, lift, carry, place and retreat points, each solved by Drake's
``InverseKinematics`` (top-down, within the joint limits) from the previous solution — and samples
the joint-space line between consecutive solutions; where the smallest singular value of the
tool's 6 × n Jacobian (rotation rows × ``controller.rot_scale``, as the task weighs them) falls
below ``MIN_SIGMA`` it returns one warning per task naming the phase.  Arms with fewer than 6
joints (``rvm1_5dof``: a 5-D top-down task by design) are not checked for that.

A 5-joint arm on ``top_down`` has another edge: near its own waist axis it cannot point the tool
down at all (``rvm1_5dof`` at z = 0.15-0.19 m: no top-down posture within its joint limits closer
than about 85 mm, where the wrist pitch reaches its −90° limit), and its Jacobian loses rank on
the way there.  The plan goes around it (``route``: a via on the far side of the axis); where no
way around was found, ``inner_reach_warnings`` follows the plan's ways (``ways.nominal_paths``)
and warns, one line per task, where one passes within ``route.INNER_MARGIN`` of that inner edge.
Measured (issue 33), before the route: tests/two_belt_pick.yaml and its mirror image in y both
swung past the base 106-108 mm from the axis; on the mirror image the arm slid into the inner edge
(6 mm from the axis, the wrist pitch at −90°, the smallest singular value 1e-4 m, torque commands
4e9 N·m) and missed; on the original it recovered after tilting the tool 33°.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable

from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.worlds.pick.route import FULL_TOP_DOWN, INNER_MARGIN, too_near
from ptint_drake.worlds.pick.ways import nominal, nominal_paths
from ptint_drake.worlds.pick.tasks import VIA_PART

MIN_SIGMA = 0.01  # m: on rvm1_6dof (rot_scale 0.1 m/rad) about a wrist pitch of 10°
SAMPLES = 12  # joint-space samples between two waypoints


def _sigma_min(plant, context, frame, q: np.ndarray, rot_scale: float) -> float:
    plant.SetPositions(context, q)
    J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3),
                                          plant.world_frame(), plant.world_frame())
    J[:3] *= rot_scale
    return float(np.linalg.svd(J, compute_uv=False)[-1])


def _waypoints(scenario, built) -> list:
    """(task, phase, x) of every waypoint after the start posture (nominal part positions), a via
    (``route``) before the approach or the carry it precedes."""
    plan, config = built.plan, built.station.config
    belts = {b.name: b for b in config.belts}
    context = built.station.plant.CreateDefaultContext()
    vias = {(s.task, "approach" if s.kind == VIA_PART else "carry"): np.asarray(s.offset)
            for s in plan.segments if s.phase == "via"}
    out = []
    for k, task in enumerate(scenario.pick.tasks):
        i_part = plan.segments[plan.segment_index(k, "approach")].index
        belt = belts[config.parts[i_part].belt]
        start = built.station.parts[i_part].EvalPoseInWorld(context).translation()
        grasp = start + belt.speed * plan.grasp_times[k] * np.asarray(belt.direction, dtype=float)
        i = plan.segment_index(k, "place")  # (an outgoing belt's place: where it is at the place time)
        place = built.targets.places[i] + np.asarray(plan.segments[i].ride) * plan.schedule.segments[i].end
        up = lambda h: np.array([0.0, 0.0, h])  # noqa: E731
        for phase, x in (("approach", grasp + up(task.clearance)), ("descend", grasp),
                         ("lift", grasp + up(task.lift_height)), ("carry", place + up(task.lift_height)),
                         ("place", place), ("retreat", place + up(task.clearance))):
            if (k, phase) in vias:
                out.append((k, "via", vias[(k, phase)]))
            out.append((k, phase, x))
    return out


def singularity_warnings(scenario, built) -> list[str]:
    """One warning per task whose path passes a singularity (module docstring); [] if none or
    if the arm has fewer than 6 joints."""
    arm = built.arm
    if arm.num_velocities() < 6:
        return []
    frame = arm.GetFrameByName(scenario.robot.end_effector)
    context = arm.CreateDefaultContext()
    rot_scale = float(getattr(scenario.controller, "rot_scale", 1.0) or 1.0)
    q = np.radians(scenario.robot.initial_q_deg)
    warned, out = set(), []
    for k, phase, x in _waypoints(scenario, built):
        solution = inverse_kinematics(arm, frame, x, q, down=True)
        if solution is None:  # unreachable: check_pick_reachable names it
            return out
        if k not in warned:
            near = _near_singular(arm, context, frame, q, solution, rot_scale)
            if near is not None:
                out.append(_warning(scenario, k, phase, *near))
                warned.add(k)
        q = solution
    return out


def _near_singular(arm, context, frame, q0: np.ndarray, q1: np.ndarray, rot_scale: float):
    """(σ_min, q) at the first sample of the joint-space line q0 → q1 below MIN_SIGMA, or None."""
    for s in np.linspace(0.0, 1.0, SAMPLES):
        q = (1.0 - s) * q0 + s * q1
        sigma = _sigma_min(arm, context, frame, q, rot_scale)
        if sigma < MIN_SIGMA:
            return sigma, q
    return None


def _warning(scenario, k: int, phase: str, sigma: float, q: np.ndarray) -> str:
    advice = ("" if scenario.controller.pinv_damping > 0.0 else
              "; the exact J⁺ is ill-conditioned there: set controller.pinv_damping (e.g. 0.01)")
    return (f"singularity: pick {k}'s {phase} passes near a singular posture of {scenario.robot.model} "
            f"(smallest singular value of the Jacobian {sigma:.3g} < {MIN_SIGMA:g} m near q = "
            f"{np.round(np.degrees(q), 1).tolist()} deg){advice}")


def inner_reach_warnings(scenario, built) -> list[str]:
    """One warning per task whose way (``ways.nominal_paths`` of the run's plan, its vias
    included) passes within ``route.INNER_MARGIN`` of the inner edge of the arm's top-down
    workspace: where ``route.plan_vias`` found no way around the base (module docstring); [] for
    other tasks and for arms of ``route.FULL_TOP_DOWN`` joints or more (no vias there)."""
    arm, plan = built.arm, built.plan
    if scenario.controller.task != "top_down" or arm.num_velocities() >= FULL_TOP_DOWN:
        return []
    world = nominal(scenario, arm)
    warned, out = set(), []
    for seg, path in zip(plan.segments, nominal_paths(world, plan)):
        if seg.task in warned:
            continue
        near = too_near(world, path)
        if near is None:
            continue
        radius, point = near
        warned.add(seg.task)
        out.append(f"reach: pick {seg.task}'s {seg.phase} passes {1e3 * radius:.0f} mm from the waist axis "
                   f"of {scenario.robot.model} (at z = {point[2]:.3f} m), within {1e3 * INNER_MARGIN:g} "
                   f"mm of where it can no longer point its tool down (no top-down posture "
                   f"{1e3 * max(radius - INNER_MARGIN, 0.0):.0f} mm from the axis), and no way around the "
                   f"base was found: the arm may tilt the tool or fold into its wrist-pitch limit there "
                   f"(keep the tray and the belts on the same side of the base, or farther from it)")
    return out
