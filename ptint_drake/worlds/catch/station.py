"""The catch station (issue 46): the KUKA iiwa 14, the full-size WSG 50-110 welded at its tip
frame, the foam ball with the truth side's air drag, on one discrete plant (1 ms, point contact,
SAP), the gripper's driver, and the formula camera (60 Hz) on the ball feeding the ballistic
estimator (``estimator: auto``).

``AddCatchStation`` adds it to a builder and returns the handles: the arm's ``state`` and
``actuation`` ports (the controller's only wiring to the plant), the gripper's ``command`` input,
the estimate's port ([p, v, a] of the ball, what the planner reads) and, for the metrics only,
the whole plant's state.  ``arm_plant`` is the arm alone (continuous): the
controller's and the planner's kinematics.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet
from pydrake.math import RigidTransform
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import JointActuatorIndex, PdControllerGains
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Demultiplexer

from ptint_drake.robot.plant import resolve_model
from ptint_drake.systems.estimation.imm import AdaptiveTargetEstimator
from ptint_drake.systems.hand.gripper import GripperDriver
from ptint_drake.systems.perception.camera import Camera
from ptint_drake.worlds.catch.ball import AddAirDrag, AddBall

FINGERS = ("left_finger_joint", "right_finger_joint")
TIP = "schunk_wsg_50_110_full_tip"


def _add_arm_and_hand(plant: MultibodyPlant, gripper):
    (arm,) = Parser(plant, "arm").AddModels(str(resolve_model("iiwa14")))
    path = resolve_model("iiwa14").parent / f"{gripper.model}.sdf"
    (hand,) = Parser(plant, "gripper").AddModels(str(path))
    plant.WeldFrames(plant.GetFrameByName(TIP, arm), plant.GetFrameByName("fingertip_center", hand),
                     RigidTransform())
    return arm, hand


def arm_plant() -> MultibodyPlant:
    """The arm alone, continuous and finalized (its ``schunk_wsg_50_110_full_tip`` frame): the
    controller's and the planner's kinematics."""
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(resolve_model("iiwa14")))
    plant.Finalize()
    return plant


@dataclass
class CatchStation:
    plant: MultibodyPlant
    arm: object
    hand: object
    ball: object
    driver: GripperDriver
    camera: Camera
    estimator: AdaptiveTargetEstimator
    state: object  # the arm's [q; v] output
    actuation: object  # the arm's torque input
    command: object  # the gripper's opening command input
    estimate: object  # the ball's [p, v, a] estimate
    stroke: float


def AddCatchStation(builder: DiagramBuilder, scenario) -> CatchStation:
    """The station of ``scenario`` (module docstring) in ``builder``."""
    g = scenario.catch.gripper
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=0.001, contact_model="point", discrete_contact_approximation="sap"), builder)
    arm, hand = _add_arm_and_hand(plant, g)
    ball = AddBall(plant)
    stroke = 0.0
    for name in FINGERS:
        joint = plant.GetJointByName(name, hand)
        stroke += joint.position_upper_limits()[0]
        joint.set_default_translation(g.initial_opening / 2)
    for index in map(JointActuatorIndex, range(plant.num_actuators())):
        actuator = plant.get_mutable_joint_actuator(index)
        if actuator.model_instance() == hand:
            actuator.set_controller_gains(PdControllerGains(p=g.kp, d=g.kd))
            actuator.set_effort_limit(g.max_force)
    left, right = (plant.GetJointByName(n, hand) for n in FINGERS)
    plant.AddCouplerConstraint(left, right, 1.0, 0.0)
    plant.Finalize()
    # the arm and its hand do not collide with themselves (as the pick station): at the start
    # posture link 7 overlaps link 5 (measured: a 10 kN contact from the first step)
    robot = GeometrySet([g for m in (arm, hand) for b in plant.GetBodyIndices(m)
                         for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))])
    scene_graph.collision_filter_manager().Apply(CollisionFilterDeclaration().ExcludeWithin(robot))
    plant.SetDefaultPositions(arm, np.radians(scenario.robot.initial_q_deg))
    AddAirDrag(builder, plant, ball)
    driver = builder.AddNamedSystem("gripper_driver", GripperDriver(stroke, g.speed, g.max_force, g.kp,
                                                                     g.initial_opening, 0.001))
    builder.Connect(driver.GetOutputPort("desired_state"), plant.get_desired_state_input_port(hand))
    builder.Connect(plant.get_state_output_port(hand), driver.GetInputPort("finger_state"))
    split = builder.AddNamedSystem("ball_state", Demultiplexer([4, 3, 6]))
    builder.Connect(plant.get_state_output_port(ball.model_instance()), split.get_input_port())
    camera = builder.AddNamedSystem("camera_0", Camera(config=scenario.measurement, seed_offset=0))
    builder.Connect(split.get_output_port(1), camera.get_x_true_input_port())
    estimator = builder.AddNamedSystem("ball_estimator", AdaptiveTargetEstimator(config=scenario.measurement))
    builder.Connect(camera.get_measurement_output_port(), estimator.get_measurement_input_port())
    return CatchStation(plant, arm, hand, ball, driver, camera, estimator, plant.get_state_output_port(arm),
                        plant.get_actuation_input_port(arm), driver.GetInputPort("command"),
                        estimator.GetOutputPort("target"), stroke)
