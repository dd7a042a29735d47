"""The simulated robot: its plant (with the scenario's deviations) and the checks before a run.

Everything here may use the model's dynamics: it builds and checks the *plant*.
The controller never sees any of it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (BodyIndex, JacobianWrtVariable, JointIndex, PrismaticJoint,
                                    RevoluteJoint, SpatialInertia, UnitInertia)
from pydrake.math import RigidTransform
from pydrake.solvers import Solve

from ptint_drake.rvm1 import bundled_models, model_path
from ptint_drake.scenario import Scenario, ScenarioError


def resolve_model(model: str) -> Path:
    """A bundled model name or a model file path; ScenarioError if neither exists."""
    if model in bundled_models():
        return model_path(model)
    path = Path(model)
    if not path.is_file():
        raise ScenarioError(
            f"robot.model: {model!r} is neither a bundled model ({', '.join(bundled_models())}) "
            f"nor an existing file")
    return path


def make_plant(scenario: Scenario) -> MultibodyPlant:
    """The continuous plant of the scenario's robot, with its damping scale applied."""
    plant = MultibodyPlant(time_step=0.0)
    path = resolve_model(scenario.robot.model)
    try:
        Parser(plant).AddModels(str(path))
    except Exception as exc:
        detail = " ".join(str(exc).split())[:300]
        raise ScenarioError(f"robot.model: cannot parse {str(path)!r}: {detail}") from None
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        if isinstance(joint, (RevoluteJoint, PrismaticJoint)):
            joint.set_default_damping(joint.default_damping() * scenario.plant.damping_scale)
    if not plant.HasFrameNamed(scenario.robot.end_effector):
        raise ScenarioError(
            f"robot.end_effector: the model has no frame named {scenario.robot.end_effector!r}")
    if scenario.plant.payload_kg > 0.0:
        frame = plant.GetFrameByName(scenario.robot.end_effector)
        payload = plant.AddRigidBody("payload", frame.body().model_instance(), SpatialInertia(
            scenario.plant.payload_kg, np.zeros(3), UnitInertia.SolidSphere(0.03)))
        plant.WeldFrames(frame, payload.body_frame(), RigidTransform())
    plant.Finalize()
    if len(scenario.robot.initial_q_deg) != plant.num_positions():
        raise ScenarioError(
            f"robot.initial_q_deg: the model has {plant.num_positions()} joints, "
            f"got {len(scenario.robot.initial_q_deg)} angles")
    return plant


def scale_masses(plant: MultibodyPlant, plant_context, scale: float) -> None:
    """Every link's mass and rotational inertia and every actuator's rotor inertia × scale
    (the ``mass_xF`` plant variant); the payload is unchanged."""
    if scale == 1.0:
        return
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        actuator.SetRotorInertia(plant_context, actuator.default_rotor_inertia() * scale)
    for index in range(1, plant.num_bodies()):
        body = plant.get_body(BodyIndex(index))
        if body.name() == "payload":
            continue
        M = body.default_spatial_inertia()
        if M.get_mass() > 0.0:
            body.SetSpatialInertiaInBodyFrame(plant_context, SpatialInertia(
                M.get_mass() * scale, M.get_com(), M.get_unit_inertia()))


def check_reachable(plant: MultibodyPlant, scenario: Scenario, samples_per_hold: int = 4) -> None:
    """Every target must be reachable at its interception time and during its hold.

    Reachability is decided by Drake's InverseKinematics with the model's joint
    limits (1 mm tolerance), started from the initial pose and from the previous
    solution.  Raises ScenarioError naming the interception.
    """
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    schedule = scenario.schedule()
    targets = scenario.targets()
    guess = np.radians(scenario.robot.initial_q_deg)
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, scenario.duration)
        for t in np.linspace(seg.end, max(t_end, seg.end), samples_per_hold):
            x = targets[i].evaluate(t)[0:3]
            ik = InverseKinematics(plant, with_joint_limits=True)
            ik.AddPositionConstraint(frame, np.zeros(3), plant.world_frame(),
                                     x - 1e-3, x + 1e-3)
            ik.prog().SetInitialGuess(ik.q(), guess)
            result = Solve(ik.prog())
            if not result.is_success():
                raise ScenarioError(
                    f"interceptions[{i}].target: position {np.round(x, 4).tolist()} m at "
                    f"t = {t:.3f} s is outside the arm's workspace")
            guess = result.GetSolution(ik.q())




def actuator_effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Effort limit of each actuator, in the plant's actuation-input order."""
    return np.array([plant.get_joint_actuator(i).effort_limit()
                     for i in plant.GetJointActuatorIndices()])


def effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Effort limit of each generalized velocity's actuator (in velocity order)."""
    return np.abs(plant.MakeActuationMatrix()) @ actuator_effort_limits(plant)


def _ik(plant, frame, x, guess):
    ik = InverseKinematics(plant, with_joint_limits=True)
    ik.AddPositionConstraint(frame, np.zeros(3), plant.world_frame(), x - 1e-3, x + 1e-3)
    ik.prog().SetInitialGuess(ik.q(), guess)
    result = Solve(ik.prog())
    return result.GetSolution(ik.q()) if result.is_success() else None


def torque_feasibility(plant: MultibodyPlant, scenario: Scenario, samples: int = 200) -> list:
    """Warnings for segments whose tf looks too short for the actuators' effort limits.

    A planning estimate (it uses the model, the controller does not): on the ideal
    surface the error follows e(t) ≈ e0 ξ(t), so the gripper needs the acceleration
    a(t) = ẍ_r(t) + e0 ξ̈(t).  ξ̈ is unbounded for β < 1/2; there the closed loop
    cannot follow it anyway and the β = 1/2 profile's bound is used.  The joint
    torque estimate is |M(q) J⁻¹ a| + |g(q)| at the segment's start and
    interception configurations.  The acceleration part scales as 1/tf², which
    gives the suggested tf.  e0 is taken from the start pose for the first
    segment and from the previous target for later ones.
    """
    from ptint_drake.systems.tbg import tbg_profile  # noqa: PLC0415

    frame = plant.GetFrameByName(scenario.robot.end_effector)
    context = plant.CreateDefaultContext()
    limits = effort_limits(plant)
    q_prev = np.radians(scenario.robot.initial_q_deg)
    plant.SetPositions(context, q_prev)
    x_prev = frame.CalcPoseInWorld(context).translation()
    targets = scenario.targets()
    warnings = []
    for i, ic in enumerate(scenario.interceptions):
        tf, beta = ic.tf, ic.beta
        e0 = x_prev - targets[i].evaluate(ic.start)[0:3]
        tau = ic.tf * np.linspace(0.01, 0.99, samples)
        xi_dd = tbg_profile(tau, tf, max(beta, 0.5))[2]
        x_end = targets[i].evaluate(ic.start + tf)[0:3]
        q_end = _ik(plant, frame, x_end, q_prev)
        configs = [q_prev] + ([q_end] if q_end is not None else [])
        need_acc = np.zeros(plant.num_velocities())
        need_g = np.zeros(plant.num_velocities())
        for q in configs:
            plant.SetPositions(context, q)
            plant.SetVelocities(context, np.zeros(plant.num_velocities()))
            M = plant.CalcMassMatrix(context)
            g = np.abs(plant.CalcGravityGeneralizedForces(context))
            J = plant.CalcJacobianTranslationalVelocity(
                context, JacobianWrtVariable.kV, frame, np.zeros(3), plant.world_frame(),
                plant.world_frame())
            Jp = np.linalg.pinv(J)
            for k, s in enumerate(tau):
                a = targets[i].evaluate(ic.start + s)[6:9] + e0 * xi_dd[k]
                need_acc = np.maximum(need_acc, np.abs(M @ (Jp @ a)))
            need_g = np.maximum(need_g, g)
        over = np.nonzero(need_acc + need_g > limits)[0]
        if len(over):
            j = int(over[np.argmax((need_acc + need_g - limits)[over])])
            room = limits[j] - need_g[j]
            if room <= 0:
                hint = "gravity alone exceeds the limit there"
            else:
                hint = f"tf ≥ {tf * np.sqrt(need_acc[j] / room):.2f} s would fit"
            warnings.append(
                f"interceptions[{i}].tf = {tf:g} s looks too short for the actuators: joint "
                f"{j + 1} needs about {need_acc[j] + need_g[j]:.1f} N·m (limit {limits[j]:g} N·m); "
                f"{hint}")
        if q_end is not None:
            q_prev, x_prev = q_end, x_end
    return warnings


def singularity_warnings(plant: MultibodyPlant, scenario: Scenario, series: dict) -> list:
    """A warning when J's smallest singular value drops below ``limits.singular_value_warning``:
    when it first did, and the time and configuration where it was smallest."""
    threshold = scenario.limits.singular_value_warning
    if threshold <= 0 or len(series["t"]) == 0:
        return []
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    context = plant.CreateDefaultContext()
    Js = np.empty((len(series["t"]), 3, plant.num_velocities()))
    origin, world = np.zeros(3), plant.world_frame()
    for k, q in enumerate(series["q"]):
        plant.SetPositions(context, q)
        Js[k] = plant.CalcJacobianTranslationalVelocity(
            context, JacobianWrtVariable.kV, frame, origin, world, world)
    smallest = np.linalg.svd(Js, compute_uv=False)[:, -1]  # one batched call
    below = np.nonzero(smallest < threshold)[0]
    if len(below) == 0:
        return []
    k = int(np.argmin(smallest))
    deg = ", ".join(f"{v:.1f}" for v in np.degrees(series["q"][k]))
    damped = scenario.controller.pinv_damping
    advice = (f"the damped pseudoinverse (λ = {damped:g} m/rad) keeps the torques bounded" if damped
              else "consider controller.pinv_damping (e.g. 0.01) for a damped pseudoinverse")
    return [f"near-singular Jacobian from t = {series['t'][below[0]]:.3f} s; smallest singular value "
            f"{smallest[k]:.2e} m/rad (< {threshold:g}) at t = {series['t'][k]:.3f} s, q = ({deg}) deg; "
            f"{advice}"]


def joint_limit_warnings(plant: MultibodyPlant, series: dict) -> list[str]:
    """Warnings for joints that went beyond the model's position or speed limits during the
    run (a continuous plant does not enforce them): which joint, how far, and when."""
    warnings = []
    for kind, values, lower, upper, unit in (
            ("position", series["q"], plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits(), "rad"),
            ("speed", series["v"], plant.GetVelocityLowerLimits(), plant.GetVelocityUpperLimits(), "rad/s")):
        for j in range(values.shape[1]):
            over = np.maximum(values[:, j] - upper[j], lower[j] - values[:, j])
            k = int(np.argmax(over))
            if len(over) and over[k] > 1e-9:
                first = float(series["t"][int(np.argmax(over > 1e-9))])
                limit = upper[j] if values[k, j] > upper[j] else lower[j]
                warnings.append(
                    f"joint {j + 1} {kind} {values[k, j]:.3g} {unit} at t = {series['t'][k]:.3f} s is "
                    f"beyond the model's limit {limit:.3g} {unit} (first beyond it at t = {first:.3f} s)")
    return warnings
