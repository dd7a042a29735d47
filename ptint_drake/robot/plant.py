"""The simulated robot: its plant, built from the model file with the scenario's plant
variants, and its actuators' effort limits.

Everything here may use the model's dynamics: it builds the *plant* (the station's,
``station.MakeStation``).  The controller never sees it.  The checks before and
after a run live in ``reachability`` and ``run_warnings``.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import ApplyMultibodyPlantConfig, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import JointIndex, PrismaticJoint, RevoluteJoint, SpatialInertia, UnitInertia

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import PlantConfig, RobotConfig, Scenario
from ptint_drake.robot.mass_scaling import scaled_copy
from ptint_drake.robot.rvm1 import bundled_models, model_path
from ptint_drake.systems.task.error import TASK_MIN_JOINTS


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


def parse_model(model: str, time_step: float = 0.0) -> MultibodyPlant:
    """The model file (``robot.model``) parsed into a plant, not finalized: continuous
    (``time_step`` 0) or discrete with that step (s)."""
    plant = MultibodyPlant(time_step=time_step)
    path = resolve_model(model)
    try:
        Parser(plant).AddModels(str(path))
    except Exception as exc:
        detail = " ".join(str(exc).split())[:300]
        raise ScenarioError(f"robot.model: cannot parse {str(path)!r}: {detail}") from None
    return plant


def make_plant(scenario: Scenario) -> MultibodyPlant:
    """The plant of the scenario's robot as it is simulated: the model file with the
    scenario's plant variants (``plant``) in its defaults — every link's mass and inertia
    and every rotor inertia × ``mass_scale`` (``mass_scaling``), joint damping ×
    ``damping_scale``, ``payload_kg`` welded at the end effector — with Drake's
    ``MultibodyPlantConfig`` of ``multibody`` applied (time step, contact approximation;
    continuous without one), finalized."""
    config = scenario.multibody
    plant = parse_model(scenario.robot.model, config.time_step if config is not None else 0.0)
    if scenario.plant.mass_scale != 1.0:
        plant = scaled_copy(plant, scenario.plant.mass_scale)
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        if isinstance(joint, (RevoluteJoint, PrismaticJoint)):
            joint.set_default_damping(joint.default_damping() * scenario.plant.damping_scale)
    if not plant.HasFrameNamed(scenario.robot.end_effector):
        raise ScenarioError(
            f"robot.end_effector: the model has no frame named {scenario.robot.end_effector!r}")
    if scenario.plant.payload_kg > 0.0:  # added after the scaling: the payload keeps its mass
        frame = plant.GetFrameByName(scenario.robot.end_effector)
        payload = plant.AddRigidBody("payload", frame.body().model_instance(), SpatialInertia(
            scenario.plant.payload_kg, np.zeros(3), UnitInertia.SolidSphere(0.03)))
        plant.WeldFrames(frame, payload.body_frame(), RigidTransform())
    if config is not None:
        _apply_config(config, plant)
    plant.Finalize()
    task, needed = scenario.controller.task, TASK_MIN_JOINTS[scenario.controller.task]
    if plant.num_velocities() < needed:
        raise ScenarioError(f"controller.task: {task!r} needs an arm with at least {needed} joints, "
                            f"{scenario.robot.model!r} has {plant.num_velocities()}")
    if len(scenario.robot.initial_q_deg) != plant.num_positions():
        default = scenario.robot.initial_q_deg == RobotConfig().initial_q_deg
        raise ScenarioError(
            f"robot.initial_q_deg: the model has {plant.num_positions()} joints, "
            f"got {len(scenario.robot.initial_q_deg)} angles"
            + (" (the default, the 3-joint rvm1's: give one angle per joint)" if default else ""))
    rest = getattr(scenario.controller, "null_space_posture_deg", None) or []
    if rest and len(rest) != plant.num_positions():
        raise ScenarioError(f"controller.null_space_posture_deg: the model has {plant.num_positions()} "
                            f"joints, got {len(rest)} angles")
    return plant


def nominal_plant(scenario: Scenario) -> MultibodyPlant:
    """The arm's model file as written — continuous, without the scenario's deviations (masses,
    damping, payload) or its world (gripper, parts): the one "nominal arm" of the package, what
    the controllers' kinematics and a model-based controller are allowed to know."""
    nominal = copy.copy(scenario)
    nominal.plant, nominal.multibody = PlantConfig(), None
    return make_plant(nominal)


def _apply_config(config: MultibodyPlantConfig, plant: MultibodyPlant) -> None:
    """Drake's ``ApplyMultibodyPlantConfig`` (the time step is the constructor's); a setting
    Drake rejects is a ScenarioError naming ``multibody``."""
    try:
        ApplyMultibodyPlantConfig(config, plant)
    except Exception as exc:  # noqa: BLE001  (Drake raises RuntimeError or ValueError)
        detail = " ".join(str(exc).split())[:300]
        raise ScenarioError(f"multibody: {detail}") from None


def actuator_effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Effort limit of each actuator, in the plant's actuation-input order."""
    return np.array([plant.get_joint_actuator(i).effort_limit()
                     for i in plant.GetJointActuatorIndices()])


def effort_limits(plant: MultibodyPlant) -> np.ndarray:
    """Effort limit of each generalized velocity's actuator (in velocity order)."""
    return np.abs(plant.MakeActuationMatrix()) @ actuator_effort_limits(plant)
