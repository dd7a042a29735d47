"""The pick-and-place station: arm, gripper, belts, parts and tray on one discrete plant.

``MakePickStation`` builds, from a ``PickWorldConfig``, a diagram in the spirit of a hardware
station (``station.MakeStation`` for the interception-only world): a discrete MultibodyPlant
(Drake's ``MultibodyPlantConfig`` + ``AddMultibodyPlant``: ``time_step`` 1 ms, the configured
contact model and discrete contact approximation), the arm parsed from its model file into its own
model instance (as ``robot.parse_model`` does), the gripper welded at the arm's end-effector frame
with its driver (``systems.hand.gripper.GripperDriver``), the belts running at their speeds, the parts
resting on them, the tray with its slots (``pick.scene``), ``PartPoses`` reading every part's
simulated motion (truth: the metrics') and ``PartTracker``, the part tracker (a sensor: what the
controller side reads).  The arm's controller sees only the arm: its state and actuation ports
carry the arm's joints and nothing of the fingers, belts or parts.

==================  =======  ================================================================
port                size     meaning
==================  =======  ================================================================
``actuation``       nu       input: the arm's joint torques (N·m), the arm's actuator order
``gripper_command`` 1        input: wanted opening between the pads (m); ≤ 0: close with the
                             force limit (``GripperDriver``)
``state``           nq+nv    output: the arm's [q; v] only (rad, rad/s)
``part_k_pose``     9        output: part k's simulated [x, ẋ, ẍ] (its centre, world; a
                             ``target`` port's layout), k = index in ``config.parts``
``part_k_rotation`` 15       output: part k's [R row-major, ω, ω̇] (a ``target_rotation`` layout)
``tracked_poses``   18·n     output: the part tracker's report, per part [p, v, R, ω]
                             (``tracker.PartTracker``: the sensor the controller side reads;
                             the ``part_k_*`` ports are truth, the metrics')
``gripper_state``   4        output: fingers [q_left, q_right, v_left, v_right] (m, m/s; q = the
                             pad's distance from the centre plane, opening = q_left + q_right)
``grip_force``      2        output: force of each finger's drive (N, + opens, − squeezes), the
                             gripper's net actuation after the force limit
``contact_results`` —        output: the plant's ContactResults (finger–part forces for metrics)
``contact_pairs``   —        output: (body A, body B, where) per contact (``ContactPairs``: the
                             contact results read once for ``collisions`` and the run's probe)
``collisions``      2·n      output: per obstacle (``PickStation.obstacles``: belts, tray, floor,
                             parts) [finger contact, other robot contact] (``CollisionProbe``)
``body_poses``      —        output: the plant's body poses (for logging parts, belts, fingers)
``plant_state``     —        output: the whole plant's [q; v] (arm, fingers, belts, parts: a replay)
``query_object``    —        output: SceneGraph's QueryObject (Meshcat / replay illustration)
``color_image``     —        output (``measurement.sensor: rgbd`` only): the camera's colour image
``depth_image``     —        output (rgbd only): its depth image with the sensor's noise (m)
==================  =======  ================================================================

Defaults hold the world: the arm at ``initial_q_deg`` at rest, the fingers at
``gripper.initial_opening``, parts resting on their belts.  The belts' servos bring them to speed
within a step; the parts, at rest at t = 0, catch up by friction within about speed / (μ g)
(≈ 13 ms at 0.1 m/s, μ = 0.8) unless ``PickStation.start_running`` sets them moving in a context.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import CollisionFilterDeclaration, GeometrySet, SceneGraph
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import ModelInstanceIndex
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.config.errors import ScenarioError
from ptint_drake.robot.plant import resolve_model
from ptint_drake.systems.hand.datasheets import check_mount
from ptint_drake.systems.hand.gripper import GripperDriver
from ptint_drake.worlds.pick.camera import AddPickCamera
from ptint_drake.worlds.pick.collisions import CollisionProbe
from ptint_drake.worlds.pick.config import PickWorldConfig, check_pick_world, grasp_width
from ptint_drake.worlds.pick.contact_pairs import ContactPairs
from ptint_drake.worlds.pick.part_pose import PartPoses
from ptint_drake.worlds.pick.tracker import TRACKER_PORT, PartTracker
from ptint_drake.worlds.pick.scene import (AddBelt, AddBin, AddFloor, AddGripper, AddPart, AddTray,
                                          gripper_stroke)


@dataclass
class PickStation:
    """The station diagram and the handles a builder of the rest (or a metric) needs."""

    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: SceneGraph
    config: PickWorldConfig
    arm: ModelInstanceIndex
    gripper: ModelInstanceIndex
    belts: list  # PrismaticJoint per belt, config order
    parts: list  # RigidBody per part, config order
    slots: list  # Frame slot_k on the tray
    driver: GripperDriver
    obstacles: list = None  # names of the ``collisions`` port's obstacles, in its order
    collision_probe: CollisionProbe = None  # the system behind the ``collisions`` port
    body_of_geometry: dict = None  # GeometryId → body index (``body_of_geometry``)

    def start_running(self, plant_context) -> None:
        """Sets, in ``plant_context``, every belt at its speed and every part moving with its belt."""
        belts = {b.name: b for b in self.config.belts}
        for joint, belt in zip(self.belts, self.config.belts):
            joint.set_translation_rate(plant_context, belt.speed)
        for body, part in zip(self.parts, self.config.parts):
            belt = belts[part.belt]
            v = belt.speed * np.asarray(belt.direction, dtype=float)
            # a free body's generalized velocity is [ω_WB; v_WB]
            self.plant.SetVelocities(plant_context, body.model_instance(), np.concatenate([np.zeros(3), v]))

    def put_in_hand(self, plant_context, k: int) -> None:
        """Sets, in ``plant_context``, part k's centre on the fingertip centre with its x axis across
        the fingers (its y along the pads), at rest — e.g. to study a hold without a pick."""
        tip = self.plant.GetFrameByName("fingertip_center", self.gripper)
        self.plant.SetFreeBodyPose(plant_context, self.parts[k], tip.CalcPoseInWorld(plant_context))
        self.plant.SetVelocities(plant_context, self.parts[k].model_instance(), np.zeros(6))


def _parse_arm(plant: MultibodyPlant, config: PickWorldConfig) -> ModelInstanceIndex:
    path = resolve_model(config.model)
    try:
        (arm,) = Parser(plant, "arm").AddModels(str(path))
    except Exception as exc:
        detail = " ".join(str(exc).split())[:300]
        raise ScenarioError(f"pick.model: cannot parse {str(path)!r}: {detail}") from None
    if not plant.HasFrameNamed(config.end_effector, arm):
        raise ScenarioError(f"pick.end_effector: the arm has no frame named {config.end_effector!r}")
    check_mount(config.gripper.model, config.end_effector, lambda name: plant.HasFrameNamed(name, arm))
    return arm


def _add_world(plant: MultibodyPlant, scene_graph: SceneGraph, config: PickWorldConfig):
    """Arm, gripper, belts, parts, tray and bins in ``plant`` (not finalized); the handles."""
    arm = _parse_arm(plant, config)
    nubs = config.contact_model == "point"
    gripper = AddGripper(plant, plant.GetFrameByName(config.end_effector, arm), config.gripper, nubs)
    stroke = gripper_stroke(plant, gripper)
    belts = [AddBelt(plant, b) for b in config.belts]
    by_name = {b.name: b for b in config.belts}
    parts = []
    for k, part in enumerate(config.parts):
        if grasp_width(part) >= stroke:
            raise ScenarioError(f"pick.parts[{k}].size: {grasp_width(part)} m across the fingers does not "
                                f"fit the gripper's {stroke} m stroke")
        parts.append(AddPart(plant, part, by_name[part.belt], nubs))
    slots = AddTray(plant, config.tray)
    bins = [AddBin(plant, box) for box in config.bins]
    floor = AddFloor(plant)
    fixed = GeometrySet([g for j in belts for g in plant.GetCollisionGeometriesForBody(j.child_body())]
                        + list(plant.GetCollisionGeometriesForBody(plant.GetBodyByName("tray"))) + [floor]
                        + [g for body in bins for g in plant.GetCollisionGeometriesForBody(body)])
    # the arm and its gripper do not collide with themselves (no self-collision avoidance is
    # planned; Drake already filters bodies joined by a joint, this also covers e.g. hand–finger)
    robot = GeometrySet([g for m in (arm, gripper) for b in plant.GetBodyIndices(m)
                         for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))])
    manager = scene_graph.collision_filter_manager()
    manager.Apply(CollisionFilterDeclaration().ExcludeWithin(fixed))
    manager.Apply(CollisionFilterDeclaration().ExcludeWithin(robot))
    return arm, gripper, belts, parts, slots


def MakePickStation(config: PickWorldConfig, measurement=None) -> PickStation:
    """The pick-and-place station of ``config`` (see the module docstring for its ports); with
    ``measurement`` (``sensor: rgbd``) it also renders its scene graph through the camera
    (``pick.camera.AddPickCamera``) and exports ``color_image`` and ``depth_image``."""
    check_pick_world(config)
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(MultibodyPlantConfig(
        time_step=config.time_step, contact_model=config.contact_model,
        discrete_contact_approximation=config.contact_approximation), builder)
    arm, gripper, belts, parts, slots = _add_world(plant, scene_graph, config)
    plant.Finalize()
    if len(config.initial_q_deg) != plant.num_positions(arm):
        raise ScenarioError(f"pick.initial_q_deg: the arm has {plant.num_positions(arm)} joints, "
                            f"got {len(config.initial_q_deg)} angles")
    plant.SetDefaultPositions(arm, np.radians(config.initial_q_deg))
    g = config.gripper
    driver = builder.AddNamedSystem("gripper_driver", GripperDriver(
        gripper_stroke(plant, gripper), g.speed, g.max_force, g.kp, g.initial_opening, config.time_step))
    builder.Connect(driver.GetOutputPort("desired_state"), plant.get_desired_state_input_port(gripper))
    builder.Connect(plant.get_state_output_port(gripper), driver.GetInputPort("finger_state"))
    for joint, belt in zip(belts, config.belts):
        source = builder.AddNamedSystem(f"{belt.name}_speed", ConstantVectorSource([0.0, belt.speed]))
        builder.Connect(source.get_output_port(), plant.get_desired_state_input_port(joint.model_instance()))
    poses = builder.AddNamedSystem("part_poses", PartPoses(plant, parts))
    builder.Connect(plant.get_body_poses_output_port(), poses.get_input_port(0))
    builder.Connect(plant.get_state_output_port(), poses.get_input_port(1))
    builder.Connect(plant.get_generalized_acceleration_output_port(), poses.get_input_port(2))
    tracker = builder.AddNamedSystem("part_tracker", PartTracker(plant, parts))
    builder.Connect(plant.get_body_poses_output_port(), tracker.GetInputPort("body_poses"))
    builder.Connect(plant.get_state_output_port(), tracker.GetInputPort("state"))
    builder.ExportOutput(tracker.get_output_port(), TRACKER_PORT)
    builder.ExportInput(plant.get_actuation_input_port(arm), "actuation")
    builder.ExportInput(driver.GetInputPort("command"), "gripper_command")
    builder.ExportOutput(plant.get_state_output_port(arm), "state")
    for k in range(len(parts)):
        builder.ExportOutput(poses.GetOutputPort(f"part_{k}_pose"), f"part_{k}_pose")
        builder.ExportOutput(poses.GetOutputPort(f"part_{k}_rotation"), f"part_{k}_rotation")
    builder.ExportOutput(plant.get_state_output_port(gripper), "gripper_state")
    builder.ExportOutput(plant.get_net_actuation_output_port(gripper), "grip_force")
    builder.ExportOutput(plant.get_contact_results_output_port(), "contact_results")
    obstacles, collisions = _collision_probe(plant, config, arm, gripper, belts, parts)
    geometry = body_of_geometry(plant, scene_graph)
    pairs = builder.AddNamedSystem("contact_pairs", ContactPairs(geometry))
    builder.AddNamedSystem("collision_probe", collisions)
    builder.Connect(plant.get_contact_results_output_port(), pairs.get_input_port())
    builder.Connect(pairs.get_output_port(), collisions.get_input_port())
    builder.ExportOutput(pairs.get_output_port(), "contact_pairs")
    builder.ExportOutput(collisions.get_output_port(), "collisions")
    builder.ExportOutput(plant.get_body_poses_output_port(), "body_poses")
    builder.ExportOutput(plant.get_state_output_port(), "plant_state")
    builder.ExportOutput(scene_graph.get_query_output_port(), "query_object")
    if measurement is not None and measurement.sensor == "rgbd":
        camera = AddPickCamera(builder, scene_graph, measurement, config)
        builder.ExportOutput(camera.color_image, "color_image")
        builder.ExportOutput(camera.depth_image, "depth_image")
    diagram = builder.Build()
    diagram.set_name("pick_station")
    return PickStation(diagram, plant, scene_graph, config, arm, gripper, belts, parts, slots, driver,
                       obstacles, collisions, geometry)


def _collision_probe(plant, config, arm, gripper, belts, parts) -> tuple:
    """The obstacles' names (belts, "tray", "floor", parts, bins) and their ``CollisionProbe``."""
    names = ([b.name for b in config.belts] + ["tray", "floor"] + [p.name for p in config.parts]
             + [b.name for b in config.bins])
    bodies = ([[j.child_body().index()] for j in belts] + [[plant.GetBodyByName("tray").index()],
                                                           [plant.world_body().index()]]
              + [[b.index()] for b in parts] + [[plant.GetBodyByName(b.name).index()] for b in config.bins])
    robot = [b for m in (arm, gripper) for b in plant.GetBodyIndices(m)]
    fingers = [plant.GetBodyByName(n, gripper).index() for n in ("left_finger", "right_finger")]
    return names, CollisionProbe(bodies, fingers, robot)


def body_of_geometry(plant: MultibodyPlant, scene_graph: SceneGraph) -> dict:
    """GeometryId → body index of every geometry of the plant's bodies (hydroelastic contacts
    report geometries)."""
    inspector = scene_graph.model_inspector()
    return {g: int(plant.GetBodyFromFrameId(inspector.GetFrameId(g)).index())
            for g in inspector.GetAllGeometryIds() if plant.GetBodyFromFrameId(inspector.GetFrameId(g))}
