"""The simulated world of a scenario as one Drake diagram with exported ports.

In the spirit of a hardware station: ``MakeStation`` builds everything the
controller does *not* decide — the plant (continuous, or discrete with the
scenario's ``multibody`` settings) with the scenario's deviations (``plant``:
masses, damping, payload, friction, disturbance), the torque saturation at the
model's effort limits, and the true moving objects — and exports the ports a
controller (or a user's own diagram) connects to.

The station owns its world: the plant variants are in the plant's defaults
(``robot.make_plant``) and its default pose is ``robot.initial_q_deg`` at rest, so
the station added to any diagram and simulated from that diagram's default context
by any ``Simulator`` is the world ``ptint run`` simulates.

=====================  ======  ================================================
port                   size    meaning
=====================  ======  ================================================
``actuation``          nu      input: commanded actuation (saturated if
                               ``limits.saturate``), in the plant's actuator order
``state``              nq+nv   output: the plant's [q; v]
``target``             9       output: true [x_r, ẋ_r, ẍ_r] of the active segment's object
``objects``            3·n     output: true position of every object
``object_rotations``   9·n     output: true orientation of every object (row-major;
                               an unturned frame for an object without one)
``color_image``        —       output (``measurement.sensor: rgbd`` only): the RGB-D
                               camera's colour image (ImageRgba8U)
``depth_image``        —       output (rgbd only): its depth image with the sensor's
                               noise (ImageDepth32F, m; 0 where missing)
=====================  ======  ================================================

With an RGB-D camera the station also holds a ``SceneGraph`` drawing the arm's visual
geometry where the plant is (a never-simulated copy of the model posed from ``state``: the
arm occludes), the objects (the camera's ``part_shape`` and ``part_size``) posed by their
motion, and the belts the perception knows (``perception.belt_regions.perception_belts``).

The station may use the model (it *is* the model); the model-free controllers
only see ``state`` (through the kinematics) and a target.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import SceneGraph
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import Saturation

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.robot.plant import actuator_effort_limits, effort_limits, make_plant, resolve_model
from ptint_drake.systems.perception.belt_regions import perception_belts
from ptint_drake.systems.perception.rgbd_camera import AddRgbdCamera
from ptint_drake.systems.perception.scene_geometry import AddArmVisuals, AddPartGeometry
from ptint_drake.systems.task.orientation import ObjectRotations
from ptint_drake.systems.task.targets import TargetSource
from ptint_drake.worlds.interception.disturbance import JointDisturbance
from ptint_drake.worlds.interception.objects import interception_schedule, interception_targets


@dataclass
class Station:
    """The station diagram and what a builder of the rest needs to know about it."""

    diagram: Diagram
    plant: MultibodyPlant
    true_targets: list
    effort_limits: np.ndarray  # per generalized velocity (inf where none)
    saturate: bool


def MakeStation(scenario: Scenario) -> Station:
    """The station of ``scenario`` (see the module docstring for its ports)."""
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("plant", make_plant(scenario))
    plant.SetDefaultPositions(np.radians(scenario.robot.initial_q_deg))  # at rest: v = 0 by default
    if scenario.limits.saturate:
        limits = actuator_effort_limits(plant)
        saturation = builder.AddNamedSystem("saturation", Saturation(-limits, limits))
        builder.Connect(saturation.get_output_port(), plant.get_actuation_input_port())
        builder.ExportInput(saturation.get_input_port(), "actuation")
    else:
        builder.ExportInput(plant.get_actuation_input_port(), "actuation")
    if JointDisturbance.needed(scenario.plant):
        p, d = scenario.plant, scenario.plant.disturbance
        try:
            disturbance = builder.AddNamedSystem("disturbance", JointDisturbance(
                plant.num_positions(), plant.num_velocities(), d.amplitude, d.frequency_hz,
                d.phase, d.step, d.step_time, p.coulomb, p.coulomb_speed))
        except ValueError as exc:
            raise ScenarioError(str(exc)) from None
        builder.Connect(plant.get_state_output_port(), disturbance.get_input_port())
        builder.Connect(disturbance.get_output_port(), plant.get_applied_generalized_force_input_port())
    targets = interception_targets(scenario)
    truth = builder.AddNamedSystem("objects", TargetSource(interception_schedule(scenario), targets))
    builder.ExportOutput(plant.get_state_output_port(), "state")
    builder.ExportOutput(truth.GetOutputPort("target"), "target")
    builder.ExportOutput(truth.GetOutputPort("objects"), "objects")
    rotations = builder.AddNamedSystem("object_rotations", ObjectRotations(targets))
    builder.ExportOutput(rotations.get_output_port(), "object_rotations")
    m = scenario.measurement
    if m is not None and m.sensor == "rgbd":
        _add_camera(builder, scenario, plant_state=plant.get_state_output_port(),
                    positions=truth.GetOutputPort("objects"), rotations=rotations.get_output_port(),
                    targets=targets)
    diagram = builder.Build()
    diagram.set_name("station")
    return Station(diagram, plant, targets, effort_limits(plant), scenario.limits.saturate)


def _add_camera(builder: DiagramBuilder, scenario: Scenario, *, plant_state, positions, rotations,
                targets) -> None:
    """The scene graph (arm visuals, objects, belts), the RGB-D camera, and its exported images."""
    m = scenario.measurement
    try:
        belts, _ = perception_belts(m, targets, scenario.duration)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    scene_graph = builder.AddNamedSystem("scene_graph", SceneGraph())
    AddArmVisuals(builder, scene_graph, str(resolve_model(scenario.robot.model)), plant_state)
    AddPartGeometry(builder, scene_graph, positions=positions, rotations=rotations, count=len(targets),
                    shape=m.camera.part_shape, size=m.camera.part_size, belts=belts)
    camera = AddRgbdCamera(builder, scene_graph, m.camera, rate_hz=m.rate_hz, seed=m.seed)
    builder.ExportOutput(camera.color_image, "color_image")
    builder.ExportOutput(camera.depth_image, "depth_image")
