"""The catch station (issue 46): the KUKA iiwa 14, the full-size WSG 50-110 welded at its tip
frame, the foam ball with the truth side's air drag, on one discrete plant (1 ms, point contact,
SAP), the gripper's driver, and the formula camera (60 Hz) on the ball (with
``measurement.sensor: rgbd``: the rendered RGB-D camera and ``ball_camera``'s sphere fit in each
depth frame) feeding the ball's estimator: the fit of its dragged flight (``flight_estimator``;
``catch.predictor: fit``, the default) or the scenario's camera estimator
(``catch.predictor: auto``, the IMM).

``AddCatchStation`` adds it to a builder and returns the handles: the arm's ``state`` and
``actuation`` ports (the controller's only wiring to the plant), the gripper's ``command`` input,
the estimate's port ([p, v, a] of the ball, what the planner reads) and, for the metrics only,
the whole plant's state.  The plant's step is ``catch.time_step`` (1 ms).

The hand's contact.  Its model gives its geometries no relaxation time (SAP's dissipation), and
SAP's default then (0.1 s, measured: the same as 0.1 given) makes a contact of the ball with the
hand a dead impact that stops the ball's approach speed within one step, a force of m Δv / h
that doubles when the step is halved (a 3 m/s drop on such a box: 110.8 N at 1 ms, 205.7 N at
0.5 ms).  The station gives them ``HAND_RELAXATION_TIME`` = 1 ms, so that the foam ball's impact
lasts ~8 ms, its force set by the ball's compliance (the same drop: 37.5 / 34.8 / 33.9 N at
1 / 0.5 / 0.25 ms, a rebound of 0.43–0.49).  ``arm_plant`` is the arm alone (continuous): the
controller's and the planner's kinematics.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, ProximityProperties, RoleAssign
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
from ptint_drake.systems.perception.rgbd_camera import AddRgbdCamera
from ptint_drake.worlds.catch.ball import BALL_DIAMETER, AddAirDrag, AddBall
from ptint_drake.worlds.catch.ball_camera import FIT_STD, BallCamera
from ptint_drake.worlds.catch.flight_estimator import FlightEstimator

FINGERS = ("left_finger_joint", "right_finger_joint")
HAND_RELAXATION_TIME = 0.001  # s (module docstring)
TIP = "schunk_wsg_50_110_full_tip"


def add_arm_and_hand(plant: MultibodyPlant, gripper):
    """The iiwa 14 and ``gripper``'s hand model welded at its tip frame, in ``plant`` (not
    finalized): (arm, hand) model instances."""
    (arm,) = Parser(plant, "arm").AddModels(str(resolve_model("iiwa14")))
    path = resolve_model("iiwa14").parent / f"{gripper.model}.sdf"
    (hand,) = Parser(plant, "gripper").AddModels(str(path))
    plant.WeldFrames(plant.GetFrameByName(TIP, arm), plant.GetFrameByName("fingertip_center", hand),
                     RigidTransform())
    return arm, hand


def _relax_hand(plant: MultibodyPlant, scene_graph, hand) -> None:
    """Give the hand's collision geometries ``HAND_RELAXATION_TIME`` (module docstring)."""
    inspector = scene_graph.model_inspector()
    for body in plant.GetBodyIndices(hand):
        for gid in plant.GetCollisionGeometriesForBody(plant.get_body(body)):
            props = ProximityProperties(inspector.GetProximityProperties(gid))
            if props.HasProperty("material", "relaxation_time"):
                props.UpdateProperty("material", "relaxation_time", HAND_RELAXATION_TIME)
            else:
                props.AddProperty("material", "relaxation_time", HAND_RELAXATION_TIME)
            scene_graph.AssignRole(plant.get_source_id(), gid, props, RoleAssign.kReplace)


def _add_ball_camera(builder: DiagramBuilder, scene_graph, m) -> tuple:
    """The rendered RGB-D camera on the station's scene graph and the ``BallCamera`` reading its
    depth; the measurement settings the estimator is given (``noise_std``: ``FIT_STD`` unless set)."""
    rgbd = AddRgbdCamera(builder, scene_graph, m.camera, rate_hz=m.rate_hz, seed=m.seed)
    camera = builder.AddNamedSystem("camera_0", BallCamera(config=m, info=rgbd.info, X_WC=rgbd.X_WC,
                                                           radius=BALL_DIAMETER / 2))
    builder.Connect(rgbd.depth_image, camera.get_depth_image_input_port())
    return camera, (m if m.noise_std else dataclasses.replace(m, noise_std=FIT_STD))


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
    estimator: object  # a FlightEstimator or an AdaptiveTargetEstimator
    state: object  # the arm's [q; v] output
    actuation: object  # the arm's torque input
    command: object  # the gripper's opening command input
    estimate: object  # the ball's [p, v, a] estimate
    stroke: float


def AddCatchStation(builder: DiagramBuilder, scenario) -> CatchStation:
    """The station of ``scenario`` (module docstring) in ``builder``."""
    g = scenario.catch.gripper
    step = scenario.catch.time_step
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=step, contact_model="point", discrete_contact_approximation="sap"), builder)
    arm, hand = add_arm_and_hand(plant, g)
    _relax_hand(plant, scene_graph, hand)
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
                                                                     g.initial_opening, step))
    builder.Connect(driver.GetOutputPort("desired_state"), plant.get_desired_state_input_port(hand))
    builder.Connect(plant.get_state_output_port(hand), driver.GetInputPort("finger_state"))
    split = builder.AddNamedSystem("ball_state", Demultiplexer([4, 3, 6]))
    builder.Connect(plant.get_state_output_port(ball.model_instance()), split.get_input_port())
    m = scenario.measurement
    if m.sensor == "rgbd":
        camera, m = _add_ball_camera(builder, scene_graph, m)
    else:
        camera = builder.AddNamedSystem("camera_0", Camera(config=m, seed_offset=0))
        builder.Connect(split.get_output_port(1), camera.get_x_true_input_port())
    chosen = (FlightEstimator if scenario.catch.predictor == "fit" else AdaptiveTargetEstimator)
    estimator = builder.AddNamedSystem("ball_estimator", chosen(config=m))
    builder.Connect(camera.get_measurement_output_port(), estimator.get_measurement_input_port())
    return CatchStation(plant, arm, hand, ball, driver, camera, estimator, plant.get_state_output_port(arm),
                        plant.get_actuation_input_port(arm), driver.GetInputPort("command"),
                        estimator.get_target_output_port(), stroke)
