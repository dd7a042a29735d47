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
joints (``rvm1_5dof``: a 5-D top-down task by design) are not checked.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable

from ptint_drake.reachability import inverse_kinematics

MIN_SIGMA = 0.01  # m: on rvm1_6dof (rot_scale 0.1 m/rad) about a wrist pitch of 10°
SAMPLES = 12  # joint-space samples between two waypoints


def _sigma_min(plant, context, frame, q: np.ndarray, rot_scale: float) -> float:
    plant.SetPositions(context, q)
    J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3),
                                          plant.world_frame(), plant.world_frame())
    J[:3] *= rot_scale
    return float(np.linalg.svd(J, compute_uv=False)[-1])


def _waypoints(scenario, built) -> list:
    """(task, phase, x) of every waypoint after the start posture (nominal part positions)."""
    plan, config = built.plan, built.station.config
    belts = {b.name: b for b in config.belts}
    context = built.station.plant.CreateDefaultContext()
    out = []
    for k, task in enumerate(scenario.pick.tasks):
        i_part = plan.segments[plan.segment_index(k, "approach")].index
        belt = belts[config.parts[i_part].belt]
        start = built.station.parts[i_part].EvalPoseInWorld(context).translation()
        grasp = start + belt.speed * plan.grasp_times[k] * np.asarray(belt.direction, dtype=float)
        place = built.targets.places[plan.segment_index(k, "place")]
        up = lambda h: np.array([0.0, 0.0, h])  # noqa: E731
        out += [(k, "approach", grasp + up(task.clearance)), (k, "descend", grasp),
                (k, "lift", grasp + up(task.lift_height)), (k, "carry", place + up(task.lift_height)),
                (k, "place", place), (k, "retreat", place + up(task.clearance))]
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
