"""Can the arm reach its targets?  Drake's InverseKinematics with the model's joint limits.

``check_reachable`` is the check before a run (a ScenarioError naming the
interception); ``inverse_kinematics`` is the one solve it and the torque estimate
(``run_warnings.torque_feasibility``) use.  For a task with orientation
(``controller.task`` pose or top_down, issue 19) the orientation the task asks for at tf
and in the hold is checked too, once the position is known to be reachable: the object's
R_r within ``ORIENTATION_TOLERANCE`` (``pose``), or the top-down grasp Rz(ψ)·Rx(π) on
either branch of ψ (``top_down``; the tool's z axis down and its x axis along the part's).

What a solve costs (issue 44: an online line asks thousands a run, ~0.6 ms each, ~1 ms a failing
one): ``inverse_kinematics`` answers two kinds of question without solving, and both answers are
the solver's own, so no caller's result changes —

- **beyond the arm's sphere of reach** (``reach_sphere``): a serial chain of revolute joints keeps
  the distance between consecutive joint origins (each pair fixed in one body; a revolute joint's
  two frames share their origin), and the second joint's distance from the first joint's axis;
  a point farther from that axis's foot than their sum (plus the position box's half-diagonal) has
  no posture — None at once.  Measured (line_assembly harsh, seed 3): 150 of the 174 failing
  solves of a sample (a reach window's scan runs the belt's whole length);
- **a question asked before** (``_ANSWERS``): the same plant and frame, the same point, start
  posture and constraints to the bit — Drake's SNOPT solve is deterministic, so the answer is the
  first one's (a copy).  Kept per plant while it lives (``weakref``), ``ANSWERS_SIZE`` at most.
  Measured (same sample): of 2298 solves, 95 repeats, all in the plan's route
  (``route._carry_turn`` and ``too_near`` ask the same postures again for each task).
"""

from __future__ import annotations

import weakref
from typing import Optional

import numpy as np
from pydrake.math import RollPitchYaw, RotationMatrix
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import Solve

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.systems.task.orientation import target_rotation_values

POSITION_TOLERANCE = 1e-3  # m, per axis
DOWN_TOLERANCE = np.radians(2.0)  # rad, of a top-down tool axis
ORIENTATION_TOLERANCE = np.radians(2.0)  # rad, of the whole tool orientation (pose, top_down)
ANSWERS_SIZE = 4096  # solves kept per plant (``_ANSWERS``, oldest dropped first)
SPHERE_SLACK = 1e-5  # m beyond the box's half-diagonal: the solver's own feasibility tolerance
# plant → {(frame, x, guess, down, R) bytes: the answer} and plant → {frame: (centre, radius) or None}
_ANSWERS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()
_SPHERES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def inverse_kinematics(plant: MultibodyPlant, frame, x: np.ndarray, guess: np.ndarray,
                       down: bool = False, R: Optional[np.ndarray] = None) -> Optional[np.ndarray]:
    """Joint positions within the model's limits that put ``frame``'s origin within
    ``POSITION_TOLERANCE`` of ``x`` (world), solved from ``guess``; None if none was found.
    ``down``: with the frame's z axis within ``DOWN_TOLERANCE`` of straight down (a top-down grasp);
    ``R`` (3 × 3, world): with the frame's orientation within ``ORIENTATION_TOLERANCE`` of it.
    Beyond the arm's sphere of reach, or asked before, without a solve (module docstring)."""
    x = np.asarray(x, dtype=float)
    sphere = reach_sphere(plant, frame)
    if sphere is not None and np.linalg.norm(x - sphere[0]) > sphere[1] + np.sqrt(3.0) * POSITION_TOLERANCE \
            + SPHERE_SLACK:
        return None
    key = (int(frame.index()), x.tobytes(), np.asarray(guess, dtype=float).tobytes(), bool(down),
           None if R is None else np.asarray(R, dtype=float).tobytes())
    answers = _ANSWERS.setdefault(plant, {})
    if key not in answers:
        if len(answers) >= ANSWERS_SIZE:
            answers.pop(next(iter(answers)))
        answers[key] = _solve(plant, frame, x, guess, down, R)
    found = answers[key]
    return None if found is None else found.copy()


def _solve(plant: MultibodyPlant, frame, x: np.ndarray, guess: np.ndarray, down: bool,
           R: Optional[np.ndarray]) -> Optional[np.ndarray]:
    """``inverse_kinematics``, solved."""
    ik = InverseKinematics(plant, with_joint_limits=True)
    ik.AddPositionConstraint(frame, np.zeros(3), plant.world_frame(),
                             x - POSITION_TOLERANCE, x + POSITION_TOLERANCE)
    if down:
        ik.AddAngleBetweenVectorsConstraint(frame, [0.0, 0.0, 1.0], plant.world_frame(), [0.0, 0.0, -1.0],
                                            0.0, DOWN_TOLERANCE)
    if R is not None:
        ik.AddOrientationConstraint(plant.world_frame(), RotationMatrix(np.asarray(R, dtype=float)), frame,
                                    RotationMatrix(), ORIENTATION_TOLERANCE)
    ik.prog().SetInitialGuess(ik.q(), guess)
    result = Solve(ik.prog())
    return result.GetSolution(ik.q()) if result.is_success() else None


def reach_sphere(plant: MultibodyPlant, frame) -> Optional[tuple]:
    """(centre, radius; m, world) of a sphere holding every point ``frame``'s origin reaches (module
    docstring), or None where the chain from the world to ``frame``'s body is not welds and revolute
    joints alone (or has none of those).  Computed once per plant and frame."""
    spheres = _SPHERES.setdefault(plant, {})
    if int(frame.index()) not in spheres:
        spheres[int(frame.index())] = _sphere(plant, frame)
    return spheres[int(frame.index())]


def _sphere(plant: MultibodyPlant, frame) -> Optional[tuple]:
    """``reach_sphere``, computed on the plant's default context (the distances it sums do not
    depend on the posture, nor does the first axis, its parent welded to the world)."""
    context = plant.CreateDefaultContext()
    joints, body = [], frame.body()
    while body.index() != plant.world_body().index():
        joint = next((plant.get_joint(j) for j in plant.GetJointIndices()
                      if plant.get_joint(j).child_body().index() == body.index()), None)
        if joint is None or joint.type_name() not in ("revolute", "weld"):
            return None
        joints.append(joint)
        body = joint.parent_body()
    moving = [j for j in reversed(joints) if j.type_name() == "revolute"]
    if not moving:
        return None
    origins = [j.frame_on_child().CalcPoseInWorld(context).translation() for j in moving]
    points = origins[1:] + [frame.CalcPoseInWorld(context).translation()]
    X_WF = moving[0].frame_on_parent().CalcPoseInWorld(context)
    axis = X_WF.rotation().multiply(np.asarray(moving[0].revolute_axis(), dtype=float))
    axis = axis / np.linalg.norm(axis)
    centre = origins[0] + axis * float(np.dot(points[0] - origins[0], axis))
    radius = float(np.linalg.norm(points[0] - centre))
    radius += sum(float(np.linalg.norm(b - a)) for a, b in zip(points[:-1], points[1:]))
    return centre, radius


def _task_rotations(task: str, rot_r) -> list:
    """The tool orientations (3 × 3) that meet the task for an object with orientation ``rot_r``
    (15 values): the object's own (``pose``), or both top-down grasps (``top_down``)."""
    R_r = np.reshape(np.asarray(rot_r[0:9], dtype=float), (3, 3))
    if task == "pose":
        return [R_r]
    psi = float(np.arctan2(R_r[1, 0], R_r[0, 0]))  # the part's x axis in the horizontal plane
    grasps = []
    for yaw in (psi, psi + np.pi):
        c, s = np.cos(yaw), np.sin(yaw)
        grasps.append(np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]]))  # Rz(ψ)·Rx(π)
    return grasps


def _orientation_field(scenario: Scenario, i: int) -> str:
    target = scenario.interceptions[i].target
    return "orientation" if target.orientation is not None else "waypoints.rpy_deg"


def _reach_orientation(plant, frame, scenario: Scenario, i: int, t: float, x, rot_r,
                       guess) -> np.ndarray:
    """A solution at position ``x`` with the orientation the task asks for at t of an object
    with orientation ``rot_r`` (15), from ``guess`` (then from the initial pose); raises
    ScenarioError naming the target's orientation if none was found."""
    task = scenario.controller.task
    starts = (guess, np.radians(scenario.robot.initial_q_deg))
    for R in _task_rotations(task, rot_r):
        for start in starts:
            solution = inverse_kinematics(plant, frame, x, start, R=R)
            if solution is not None:
                return solution
    rpy = np.degrees(RollPitchYaw(RotationMatrix(np.reshape(rot_r[0:9], (3, 3)))).vector())
    what = "a top-down grasp of" if task == "top_down" else "the orientation"
    raise ScenarioError(
        f"interceptions[{i}].target.{_orientation_field(scenario, i)}: the arm cannot reach {what} "
        f"rpy {np.round(rpy, 1).tolist()} deg at {np.round(x, 4).tolist()} m, t = {t:.3f} s "
        f"(controller.task {task}, within {np.degrees(ORIENTATION_TOLERANCE):g} deg)")


def check_reachable(plant: MultibodyPlant, scenario: Scenario, schedule, targets: list,
                    samples_per_hold: int = 4) -> None:
    """Every target must be reachable at its interception time and during its hold: its
    position, and for a task with orientation the orientation the task asks for.

    ``schedule`` and ``targets``: the interception world's segments and objects.  Solved from
    the initial pose and then from the previous solution.  Raises
    ScenarioError naming the interception (``.target``: the position; ``.target.orientation``
    or ``.target.waypoints.rpy_deg``: the orientation).
    """
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    guess = np.radians(scenario.robot.initial_q_deg)
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, scenario.duration)
        for t in np.linspace(seg.end, max(t_end, seg.end), samples_per_hold):
            x = targets[i].evaluate(t)[0:3]
            solution = inverse_kinematics(plant, frame, x, guess)
            if solution is None:
                raise ScenarioError(
                    f"interceptions[{i}].target: position {np.round(x, 4).tolist()} m at "
                    f"t = {t:.3f} s is outside the arm's workspace")
            if scenario.controller.task != "position":
                rot_r = target_rotation_values(targets[i], t)
                solution = _reach_orientation(plant, frame, scenario, i, t, x, rot_r, solution)
            guess = solution
