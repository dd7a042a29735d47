"""What the camera renders besides the arm: the parts, posed by their motion, and the belts.

``PartGeometry`` registers with a ``SceneGraph`` one frame per part (a box or an upright
cylinder of the configured size, its centre at the frame's origin) and the belts as anchored
slabs under their top surfaces; its output ``geometry_pose`` poses the parts from the input
``positions`` (3 per part) and ``rotations`` (9 per part, row-major), e.g. a ``TargetSource``'s
``objects`` and ``ObjectRotations``.  ``AddArmVisuals`` adds a second, never-simulated copy of
the arm's model registered with the scene graph whose geometry is posed from the simulated
plant's state (Drake's ``MultibodyPositionToGeometryPose``), so the arm is drawn — and
occludes — where it is, without changing the simulated plant.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.geometry import (Box, Cylinder, FramePoseVector, GeometryFrame, GeometryInstance,
                              IllustrationProperties, PerceptionProperties, RenderLabel, Rgba, SceneGraph)
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.rendering import MultibodyPositionToGeometryPose

from ptint_drake.systems.perception.part_fit import BeltRegion

PART_COLOR = Rgba(0.85, 0.45, 0.1, 1.0)
BELT_COLOR = Rgba(0.2, 0.2, 0.22, 1.0)
BELT_THICKNESS = 0.02  # m, of a drawn belt slab


def visual_instance(X, shape, name: str, color: Rgba) -> GeometryInstance:
    """A geometry drawn for illustration and perception (diffuse ``color``)."""
    inst = GeometryInstance(X, shape, name)
    illustration = IllustrationProperties()
    illustration.AddProperty("phong", "diffuse", color)
    inst.set_illustration_properties(illustration)
    perception = PerceptionProperties()
    perception.AddProperty("phong", "diffuse", color)
    perception.AddProperty("label", "id", RenderLabel(len(name)))
    inst.set_perception_properties(perception)
    return inst


def part_shape(shape: str, size):
    """The Drake shape of a box [x, y, z] or an upright cylinder [diameter, height]."""
    if shape == "box":
        return Box(*[float(v) for v in size])
    return Cylinder(0.5 * float(size[0]), float(size[1]))


class PartGeometry(LeafSystem):
    """Parts and belts in a ``SceneGraph`` (see the module docstring)."""

    def __init__(self, scene_graph: SceneGraph, *, count: int, shape: str, size, belts: list[BeltRegion]):
        super().__init__()
        self._source = scene_graph.RegisterSource("parts")
        self._frames = []
        for k in range(count):
            frame = scene_graph.RegisterFrame(self._source, GeometryFrame(f"part_{k}"))
            scene_graph.RegisterGeometry(self._source, frame, visual_instance(
                RigidTransform(), part_shape(shape, size), f"part_{k}", PART_COLOR))
            self._frames.append(frame)
        for i, belt in enumerate(belts):
            u, v = belt.frame()
            R = RotationMatrix(np.column_stack([u, v, [0.0, 0.0, 1.0]]))
            X = RigidTransform(R, np.asarray(belt.center, float) - [0.0, 0.0, 0.5 * BELT_THICKNESS])
            scene_graph.RegisterAnchoredGeometry(self._source, visual_instance(
                X, Box(belt.length, belt.width, BELT_THICKNESS), f"belt_{i}", BELT_COLOR))
        self._positions = self.DeclareVectorInputPort("positions", 3 * count)
        self._rotations = self.DeclareVectorInputPort("rotations", 9 * count)
        self._poses = self.DeclareAbstractOutputPort(
            "geometry_pose", lambda: AbstractValue.Make(FramePoseVector()), self._calc)

    @property
    def source_id(self):
        return self._source

    def _calc(self, context, output) -> None:
        x = self._positions.Eval(context)
        R = self._rotations.Eval(context)
        poses = output.get_mutable_value()
        poses.clear()
        for k, frame in enumerate(self._frames):
            rotation = RotationMatrix(np.reshape(R[9 * k:9 * k + 9], (3, 3)))
            poses.set_value(frame, RigidTransform(rotation, x[3 * k:3 * k + 3]))


def AddPartGeometry(builder: DiagramBuilder, scene_graph: SceneGraph, *, positions: OutputPort,
                    rotations: OutputPort, count: int, shape: str, size, belts: list[BeltRegion]
                    ) -> PartGeometry:
    """``PartGeometry`` added and wired: posed from ``positions`` and ``rotations``."""
    parts = builder.AddNamedSystem("part_geometry", PartGeometry(
        scene_graph, count=count, shape=shape, size=size, belts=belts))
    builder.Connect(positions, parts.GetInputPort("positions"))
    builder.Connect(rotations, parts.GetInputPort("rotations"))
    builder.Connect(parts.get_output_port(), scene_graph.get_source_pose_port(parts.source_id))
    return parts


def AddArmVisuals(builder: DiagramBuilder, scene_graph: SceneGraph, model_path: str, state: OutputPort
                  ) -> MultibodyPlant:
    """The arm's visual geometry posed from ``state`` ([q; v] of a plant of the same model)."""
    visual = MultibodyPlant(0.0)
    visual.RegisterAsSourceForSceneGraph(scene_graph)
    Parser(visual).AddModels(str(model_path))
    visual.Finalize()
    to_pose = builder.AddNamedSystem("arm_visual_poses", MultibodyPositionToGeometryPose(
        visual, input_multibody_state=True))
    builder.Connect(state, to_pose.get_input_port())
    builder.Connect(to_pose.get_output_port(), scene_graph.get_source_pose_port(visual.get_source_id()))
    return visual
