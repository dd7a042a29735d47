"""What a pick-and-place plant holds besides the arm: the gripper, the belts, the parts and the
tray, added to a not yet finalized MultibodyPlant (``world.MakePickStation`` calls these).

- **Gripper** (``AddGripper``): parsed from its SDFormat file into its own model instance and
  welded so its frame ``fingertip_center`` coincides with the arm's end-effector frame; its two
  finger joints become Drake PD-controlled actuators (gains ``kp``, ``kd``; effort limit =
  ``max_force``), solved implicitly by the discrete (SAP-family) contact solver.
- **Belt** (``AddBelt``): a slab in its own model instance on a prismatic joint along the belt's
  direction, whose actuator is a PD-controlled *velocity servo* (kp = 0, kd = BELT_KD, desired
  velocity = the belt speed): it keeps the speed under the parts' friction loads to within
  load / BELT_KD (≈ 1e-5 m/s per newton).  Parts ride it by friction.
- **Part** (``AddPart``): a free box or cylinder (size, mass, friction) in its own model instance,
  whose default pose rests it on its belt.
- **Tray** (``AddTray``): a welded plate; each slot is a frame ``slot_k`` on its top surface with
  a thin marker visual (the place pose of a part's centre is ``slot_k`` raised by half its height).
- **Bin** (``AddBin``): an open box welded to the world, its floor and four walls boxes
  (``bin_boxes``); a part is let go over it (``bin_drop``) and counts when it rests inside (``in_bin``).
- **Floor** (``AddFloor``): a 4 × 4 × 0.1 m slab welded to the world, its top surface at z = FLOOR_Z = 0,
  the plane the arm's pedestal stands on (models/README.md): a part that leaves the hand or falls
  off a belt comes to rest there, so its place error stays finite.

Contact: every collision geometry carries point-contact properties (friction, stiffness,
Hunt–Crossley dissipation) and hydroelastic ones — the parts compliant (modulus HYDRO_MODULUS),
the belts, tray and floor compliant (SURFACE_MODULUS), the finger pads compliant (1 MPa rubber,
models/README.md), the arm's links, palm and finger stems rigid — so every pair that can touch is
rigid–compliant or compliant–compliant and all three Drake contact models work (strict
``hydroelastic`` included).  With point contact (``contact_model: point``) parts and pads also get small
corner spheres (``AddPointContactNubs``).  The friction of a pair is Drake's combination
2 μ₁μ₂ / (μ₁ + μ₂).
"""

from __future__ import annotations

from functools import lru_cache
from pathlib import Path

import numpy as np
from pydrake.geometry import (AddCompliantHydroelasticProperties, AddContactMaterial,
                              AddRigidHydroelasticProperties, Box, Cylinder, ProximityProperties, Sphere)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, CoulombFriction, MultibodyPlant
from pydrake.multibody.tree import (FixedOffsetFrame, JointActuatorIndex, ModelInstanceIndex,
                                    PdControllerGains, PrismaticJoint, SpatialInertia)
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.part_shape import footprint_radius
from ptint_drake.robot.rvm1 import model_path
from ptint_drake.worlds.pick.config import BeltConfig, BinConfig, GripperConfig, PartConfig, TrayConfig

BELT_KD = 1e5  # N·s/m: the belt's velocity servo (implicit, so any stiffness is stable)
BELT_FORCE = 1e4  # N: the belt drive's force limit
POINT_STIFFNESS = 1e5  # N/m: point-contact stiffness of parts, belts and tray
DISSIPATION = 5.0  # s/m: Hunt–Crossley dissipation
HYDRO_MODULUS = 1e7  # Pa: hydroelastic modulus of the parts (compliant)
# Pa: hydroelastic modulus of the belts, the tray and the floor (compliant, so that the arm's rigid
# links touching them is a rigid–compliant pair strict hydroelastic contact can compute; assumption)
SURFACE_MODULUS = 1e8
SURFACE_RESOLUTION = 0.02  # m: their mesh resolution hint (a compliant box's mesh does not use it)
NUB_RADIUS = 0.001  # m: the point-contact spheres at part and pad corners (``AddPointContactNubs``)
FINGER_JOINTS = ("left_finger_joint", "right_finger_joint")
PAD_EDGE = 0.01 - NUB_RADIUS  # m: pad nubs from the pad centre (models/rvm1_gripper.sdf: 20 mm pads)
PAD_FRICTION = 1.0  # 1: the pads' friction (models/rvm1_gripper.sdf)
FLOOR_Z = 0.0  # m: the floor's surface, the plane the arm's pedestal stands on (models/README.md)
FLOOR_FRICTION = 0.8  # 1: the floor's Coulomb friction (assumption)
FLOOR_SIZE = (4.0, 4.0, 0.1)  # m: the floor slab (a box: Drake warns about rigid half-spaces)


def contact_properties(friction: float, resolution: float = 0.0,
                       modulus: float = HYDRO_MODULUS) -> ProximityProperties:
    """Point-contact properties with Coulomb friction μ (static = dynamic), and hydroelastic ones:
    compliant (``modulus``, Pa) with a mesh of ``resolution`` (m), or rigid when it is 0."""
    props = ProximityProperties()
    AddContactMaterial(dissipation=DISSIPATION, point_stiffness=POINT_STIFFNESS,
                       friction=CoulombFriction(friction, friction), properties=props)
    if resolution > 0.0:
        AddCompliantHydroelasticProperties(resolution, modulus, props)
    else:
        AddRigidHydroelasticProperties(props)
    return props


def box_corners(size, inset: float) -> list:
    """The 8 corners of a centred box of ``size``, each moved ``inset`` inward along every axis."""
    half = np.asarray(size, dtype=float) / 2 - inset
    return [half * np.array([sx, sy, sz]) for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]


def AddPointContactNubs(plant: MultibodyPlant, body, points, friction: float, name: str) -> None:
    """Spheres of radius NUB_RADIUS at ``points`` (body frame) for point contact: a box-on-box
    point contact is one deepest point that wanders between corners (the part rocks and a grasp
    swivels about the line between the pads); a few spheres at the corners give a contact polygon."""
    props = ProximityProperties()
    AddContactMaterial(dissipation=DISSIPATION, point_stiffness=POINT_STIFFNESS,
                       friction=CoulombFriction(friction, friction), properties=props)
    for i, p in enumerate(points):
        plant.RegisterCollisionGeometry(body, RigidTransform(p), Sphere(NUB_RADIUS), f"{name}_nub{i}", props)


def gripper_path(model: str) -> Path:
    """A bundled gripper name (models/<name>.sdf) or an SDFormat file path; ScenarioError if neither."""
    bundled = model_path(model).with_suffix(".sdf")
    if bundled.is_file():
        return bundled
    if not Path(model).is_file():
        raise ScenarioError(f"gripper.model: {model!r} is neither a bundled gripper nor an existing file")
    return Path(model)


def AddGripper(plant: MultibodyPlant, end_effector, config: GripperConfig,
               nubs: bool = False) -> ModelInstanceIndex:
    """Parses the gripper into ``plant`` and welds its ``fingertip_center`` onto the frame
    ``end_effector``; sets the finger actuators' PD gains and force limit and the default
    opening; with ``nubs``, spheres at the 4 corners of each pad's inner face (point contact).
    Returns its model instance."""
    (gripper,) = Parser(plant, "gripper").AddModels(str(gripper_path(config.model)))
    if nubs:
        for name, side in (("left_finger", -1.0), ("right_finger", 1.0)):
            edges = (-PAD_EDGE, PAD_EDGE)
            corners = [np.array([side * NUB_RADIUS, y, z]) for y in edges for z in edges]
            AddPointContactNubs(plant, plant.GetBodyByName(name, gripper), corners, PAD_FRICTION, name)
    plant.WeldFrames(end_effector, plant.GetFrameByName("fingertip_center", gripper), RigidTransform())
    stroke = 0.0
    for name in FINGER_JOINTS:
        joint = plant.GetJointByName(name, gripper)
        stroke += joint.position_upper_limits()[0]
        joint.set_default_translation(config.initial_opening / 2)
    for index in map(JointActuatorIndex, range(plant.num_actuators())):  # (per-instance lists need Finalize)
        actuator = plant.get_mutable_joint_actuator(index)
        if actuator.model_instance() != gripper:
            continue
        actuator.set_controller_gains(PdControllerGains(p=config.kp, d=config.kd))
        actuator.set_effort_limit(config.max_force)
    # the jaws of a parallel gripper are geared together (rack and pinion): a coupler keeps them
    # symmetric about the fingertip centre, else two force-limited drives squeezing a part leave
    # it free to slide between them (measured: 14 mm while carried); SAP-family solvers only
    left, right = (plant.GetJointByName(n, gripper) for n in FINGER_JOINTS)
    plant.AddCouplerConstraint(left, right, 1.0, 0.0)
    if not 0.0 <= config.initial_opening <= stroke + 1e-12:
        raise ScenarioError(f"gripper.initial_opening: {config.initial_opening} m is outside the "
                            f"gripper's stroke 0 … {stroke} m")
    return gripper


def gripper_stroke(plant: MultibodyPlant, gripper: ModelInstanceIndex) -> float:
    """The largest opening between the pads (m): the sum of the finger joints' upper limits."""
    return float(sum(plant.GetJointByName(n, gripper).position_upper_limits()[0] for n in FINGER_JOINTS))


def finger_extent(plant: MultibodyPlant, scene_graph, gripper: ModelInstanceIndex) -> tuple:
    """(reach, top, thickness) of the fingers in the fingertip-centre frame, from their collision
    boxes: how far they reach past the fingertip centre along the approach, how far their top is
    before it (both m, positive), and the finger's thickness outward of the pad's face."""
    inspector = scene_graph.model_inspector()
    reach, top, thickness = 0.0, 0.0, 0.0
    for name in ("left_finger", "right_finger"):
        body = plant.GetBodyByName(name, gripper)
        for g in plant.GetCollisionGeometriesForBody(body):
            shape = inspector.GetShape(g)
            if not isinstance(shape, Box):
                continue
            X = inspector.GetPoseInFrame(g)
            half = np.array([shape.width(), shape.depth(), shape.height()]) / 2
            corners = np.array([X.multiply(half * np.array([sx, sy, sz]))
                                for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            reach, top = max(reach, corners[:, 2].max()), max(top, -corners[:, 2].min())
            thickness = max(thickness, np.abs(corners[:, 0]).max())
    return reach, top, thickness


@lru_cache(maxsize=None)
def hand_size(model: str) -> tuple:
    """(reach, top, thickness, stroke) of the gripper ``model`` (``GripperConfig.model``; m):
    ``finger_extent`` and ``gripper_stroke`` from its model alone, parsed once a process (the plan
    of every task, the planning scene of every replan and the slot warnings ask it of the same
    model)."""
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
    (gripper,) = Parser(plant, "gripper").AddModels(str(gripper_path(model)))
    plant.Finalize()
    reach, top, thickness = finger_extent(plant, scene_graph, gripper)
    return float(reach), float(top), float(thickness), gripper_stroke(plant, gripper)


def belt_frame(belt: BeltConfig) -> RigidTransform:
    """Pose of the belt's top-surface centre at t = 0; its x axis = the direction of travel."""
    d = np.asarray(belt.direction, dtype=float)
    return RigidTransform(RotationMatrix.MakeZRotation(float(np.arctan2(d[1], d[0]))), belt.center)


def AddBelt(plant: MultibodyPlant, belt: BeltConfig) -> PrismaticJoint:
    """The belt's slab on its prismatic joint with a speed servo; returns the joint."""
    instance = plant.AddModelInstance(belt.name)
    size = [belt.length, belt.width, belt.thickness]
    body = plant.AddRigidBody(belt.name, instance, SpatialInertia.SolidBoxWithMass(belt.mass, *size))
    X_BG = RigidTransform([0.0, 0.0, -belt.thickness / 2])
    plant.RegisterCollisionGeometry(body, X_BG, Box(*size), "belt", _surface_properties(belt.friction))
    plant.RegisterVisualGeometry(body, X_BG, Box(*size), "belt", [0.15, 0.15, 0.17, 1.0])
    rail = plant.AddFrame(_fixed_frame(plant, f"{belt.name}_rail", belt_frame(belt)))
    joint = plant.AddJoint(PrismaticJoint(f"{belt.name}_drive", rail, body.body_frame(), [1.0, 0.0, 0.0]))
    actuator = plant.AddJointActuator(f"{belt.name}_motor", joint, BELT_FORCE)
    actuator.set_controller_gains(PdControllerGains(p=0.0, d=BELT_KD))
    return joint


def part_shape(part: PartConfig):
    """The part's Drake shape and its height (m)."""
    if part.shape == "box":
        return Box(*part.size), part.size[2]
    return Cylinder(part.size[0] / 2, part.size[1]), part.size[1]


def part_inertia(part: PartConfig) -> SpatialInertia:
    """A solid box or vertical cylinder of the part's mass, about its centre."""
    if part.shape == "box":
        return SpatialInertia.SolidBoxWithMass(part.mass, *part.size)
    return SpatialInertia.SolidCylinderWithMass(part.mass, part.size[0] / 2, part.size[1], [0.0, 0.0, 1.0])


def part_start_pose(part: PartConfig, belt: BeltConfig) -> RigidTransform:
    """The part's centre at t = 0: ``offset`` along its belt and ``lateral`` across it, resting on
    it, turned ``yaw_deg``."""
    _, height = part_shape(part)
    X_WB = belt_frame(belt)
    p = X_WB.multiply(np.array([part.offset, part.lateral, height / 2]))
    return RigidTransform(RotationMatrix.MakeZRotation(np.radians(part.yaw_deg)), p)


def AddPart(plant: MultibodyPlant, part: PartConfig, belt: BeltConfig, nubs: bool = False):
    """The part as a free body resting on ``belt`` (its default pose), with corner spheres for
    point contact if ``nubs`` (a box's 8 corners, a cylinder's 2 × ``RIM_NUBS`` rim points);
    returns the body."""
    instance = plant.AddModelInstance(part.name)
    body = plant.AddRigidBody(part.name, instance, part_inertia(part))
    shape, height = part_shape(part)
    props = contact_properties(part.friction, min(part.size) / 2)
    plant.RegisterCollisionGeometry(body, RigidTransform(), shape, part.name, props)
    plant.RegisterVisualGeometry(body, RigidTransform(), shape, part.name, [0.2, 0.5, 0.85, 1.0])
    if nubs:
        AddPointContactNubs(plant, body, _part_nub_points(part), part.friction, part.name)
    plant.SetDefaultFloatingBaseBodyPose(body, part_start_pose(part, belt))
    return body


# a cylinder's rim points per end: every 22.5°, so that pads closing at any yaw meet a nub within
# r (1 − cos 11.25°) = 0.3 mm of the rim (30 mm disc).  With 4 (every 90°), pads closing 45° off
# them pressed the bare cylinder 1.6 mm deep each side at the 30 N grip: the opening read 26.8 mm,
# "empty" (line_two_belts_rgbd, whose camera gives a disc no yaw; the pose sensor gave the body's).
RIM_NUBS = 16


def _part_nub_points(part: PartConfig) -> list:
    if part.shape == "box":
        return box_corners(part.size, NUB_RADIUS)
    r, h = part.size[0] / 2 - NUB_RADIUS, part.size[1] / 2 - NUB_RADIUS
    angles = np.arange(RIM_NUBS) * 2.0 * np.pi / RIM_NUBS
    return [np.array([r * np.cos(a), r * np.sin(a), z]) for a in angles for z in (-h, h)]


def tray_pose(tray: TrayConfig) -> RigidTransform:
    """The tray's top-surface centre, turned ``yaw_deg`` about the vertical."""
    return RigidTransform(RollPitchYaw(0.0, 0.0, np.radians(tray.yaw_deg)), tray.center)


def slot_pose(tray: TrayConfig, k: int) -> RigidTransform:
    """X_WS of slot k: the tray's pose times the slot's offset and yaw on its top surface."""
    slot = tray.slots[k]
    return tray_pose(tray).multiply(RigidTransform(RotationMatrix.MakeZRotation(np.radians(slot.yaw_deg)),
                                                   [slot.offset[0], slot.offset[1], 0.0]))


def AddTray(plant: MultibodyPlant, tray: TrayConfig) -> list:
    """The welded plate with a frame ``slot_k`` per slot; returns the slot frames."""
    instance = plant.AddModelInstance("tray")
    body = plant.AddRigidBody("tray", instance, SpatialInertia.SolidBoxWithMass(1.0, *tray.size))
    X_TG = RigidTransform([0.0, 0.0, -tray.size[2] / 2])
    plant.RegisterCollisionGeometry(body, X_TG, Box(*tray.size), "tray", _surface_properties(tray.friction))
    plant.RegisterVisualGeometry(body, X_TG, Box(*tray.size), "tray", [0.6, 0.45, 0.25, 1.0])
    plant.WeldFrames(plant.world_frame(), body.body_frame(), tray_pose(tray))
    slots = []
    for k, slot in enumerate(tray.slots):
        X_TS = RigidTransform(RotationMatrix.MakeZRotation(np.radians(slot.yaw_deg)),
                              [slot.offset[0], slot.offset[1], 0.0])
        slots.append(plant.AddFrame(_fixed_frame(plant, f"slot_{k}", X_TS, body.body_frame())))
        plant.RegisterVisualGeometry(body, X_TS.multiply(RigidTransform([0.0, 0.0, 0.0005])),
                                     Box(0.03, 0.004, 0.001), f"slot_{k}", [0.1, 0.7, 0.2, 1.0])
    return slots


BIN_DROP_CLEARANCE = 0.01  # m: a part's bottom above a bin's walls where the fingers let it go (assumption)
BIN_GAP = 0.005  # m: between the drop points of a bin's grid, and from its walls (``bin_spots``)
BIN_RGBA = [0.35, 0.5, 0.35, 1.0]


def bin_boxes(box: BinConfig) -> list:
    """The bin's floor and four walls, each (name, pose in the world, size [x, y, z] m): an open box
    aligned with the world's axes, its inner floor's centre at ``center``, ``size`` inside,
    ``wall`` thick (the one description the station and the planning model both build)."""
    c, (ix, iy, depth), w = np.asarray(box.center, dtype=float), box.size, box.wall
    up = depth / 2
    return [("floor", RigidTransform(c + [0.0, 0.0, -w / 2]), [ix + 2 * w, iy + 2 * w, w]),
            ("wall_x-", RigidTransform(c + [-(ix + w) / 2, 0.0, up]), [w, iy + 2 * w, depth]),
            ("wall_x+", RigidTransform(c + [(ix + w) / 2, 0.0, up]), [w, iy + 2 * w, depth]),
            ("wall_y-", RigidTransform(c + [0.0, -(iy + w) / 2, up]), [ix, w, depth]),
            ("wall_y+", RigidTransform(c + [0.0, (iy + w) / 2, up]), [ix, w, depth])]


def bin_drop(box: BinConfig, part: PartConfig) -> np.ndarray:
    """Where the place phase takes a part's centre over ``box``: above its centre, the part's
    bottom ``BIN_DROP_CLEARANCE`` above the walls' top (the fingers open there, the part drops)."""
    _, height = part_shape(part)
    return np.asarray(box.center, dtype=float) + [0.0, 0.0, box.size[2] + BIN_DROP_CLEARANCE + height / 2]


def bin_spots(box: BinConfig, part: PartConfig) -> list:
    """[(x, y)] m from ``box``'s centre: the drop points of a grid over its inner floor for
    ``part``, row by row — each a footprint (a cylinder's diameter, a box's top diagonal: any yaw)
    plus ``BIN_GAP`` from the next and from the walls; the centre alone where one fits.  Parts let go
    over one point stack (a Panda line of 25 mm pucks: the third rested above the 50 mm walls)."""
    pitch = 2.0 * footprint_radius(part.shape, part.size) + BIN_GAP
    counts = [max(1, int((float(box.size[i]) - BIN_GAP) // pitch)) for i in (0, 1)]
    axes = [[(j - (n - 1) / 2) * pitch for j in range(n)] for n in counts]
    return [(x, y) for y in axes[1] for x in axes[0]]


def in_bin(box: BinConfig, p: np.ndarray) -> bool:
    """The point ``p`` (a part's centre, world) is inside the bin's inner box, below its walls' top."""
    d = np.asarray(p, dtype=float) - box.center
    return bool(abs(d[0]) <= box.size[0] / 2 and abs(d[1]) <= box.size[1] / 2 and 0.0 <= d[2] <= box.size[2])


def AddBin(plant: MultibodyPlant, box: BinConfig):
    """The bin as a body welded to the world (its floor and walls, ``bin_boxes``); returns the body."""
    instance = plant.AddModelInstance(box.name)
    body = plant.AddRigidBody(box.name, instance, SpatialInertia.SolidBoxWithMass(1.0, *box.size))
    plant.WeldFrames(plant.world_frame(), body.body_frame(), RigidTransform())
    for name, X, size in bin_boxes(box):
        plant.RegisterCollisionGeometry(body, X, Box(*size), name, _surface_properties(box.friction))
        plant.RegisterVisualGeometry(body, X, Box(*size), name, BIN_RGBA)
    return body


def AddFloor(plant: MultibodyPlant):
    """The floor: a FLOOR_SIZE slab welded to the world, centred under the arm's base, its top
    surface at z = FLOOR_Z; returns its GeometryId."""
    X_WF = RigidTransform([0.0, 0.0, FLOOR_Z - FLOOR_SIZE[2] / 2])
    return plant.RegisterCollisionGeometry(plant.world_body(), X_WF, Box(*FLOOR_SIZE), "floor",
                                           _surface_properties(FLOOR_FRICTION))


def _surface_properties(friction: float) -> ProximityProperties:
    """Contact properties of a belt, the tray or the floor: compliant hydroelastic (SURFACE_MODULUS)."""
    return contact_properties(friction, SURFACE_RESOLUTION, SURFACE_MODULUS)


def _fixed_frame(plant: MultibodyPlant, name: str, X, parent=None) -> FixedOffsetFrame:
    return FixedOffsetFrame(name, parent if parent is not None else plant.world_frame(), X)
