"""``DriveDiagram``: the controller side of ``ptint drive`` as one diagram — the scenario's
controller in its slot between the arm's reported state and the torque command, with the world's
own controller side (``World.controller_side``) where it has one (``hardware.drive``'s docstring)."""

from __future__ import annotations

import copy
import dataclasses

from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import PassThrough

from ptint_drake.config.schema import Scenario
from ptint_drake.controllers import AddControllerTo, TargetView
from ptint_drake.hardware.sim_hardware import link_period
from ptint_drake.robot.plant import nominal_plant
from ptint_drake.worlds.registry import objects_of, schedule_of, world_of


def DriveDiagram(scenario: Scenario):
    """(diagram, controller handles, joint count, the world's controller side or None:
    ``World.controller_side``, e.g. a world's targets, gripper sequence and grasp observer) of the
    scenario's controller alone (module docstring).  Inputs: ``state`` (the arm's [q; v]); with a
    controller side also ``tracked_poses`` (a pose tracker's report, ``worlds.base.TRACKED_SIZE``
    a body; a station that has one) or ``depth_image``, and ``gripper`` ([fingers (4), drive
    forces (2)], as ``link.unpack_wsg_status`` gives them).  Outputs: ``actuation``; with a
    controller side also ``grasp_state``."""
    plant = nominal_plant(scenario)
    builder = DiagramBuilder()
    n = plant.num_positions() + plant.num_velocities()
    state = builder.AddNamedSystem("status_state", PassThrough(n))
    actuation = builder.AddNamedSystem("command_torque", PassThrough(plant.num_actuators()))
    unsampled = copy.copy(scenario)  # the hardware samples and holds: no hold of its own here
    unsampled.controller = dataclasses.replace(scenario.controller, control_period=0.0)
    schedule, targets = schedule_of(scenario), objects_of(scenario)
    # the world's own controller side (its targets, gripper sequence and grasp observer), if any
    side = world_of(scenario).controller_side(builder, scenario, link_period(scenario))
    target = side.target if side is not None else TargetView(builder, None, unsampled, schedule, targets)
    handles = AddControllerTo(
        builder,
        plant=plant,
        frame=plant.GetFrameByName(scenario.robot.end_effector),
        schedule=schedule,
        state=state.get_output_port(),
        actuation=actuation.get_input_port(),
        scenario=unsampled,
        target=target,
        targets=targets,
    )
    builder.ExportInput(state.get_input_port(), "state")
    builder.ExportOutput(actuation.get_output_port(), "actuation")
    diagram = builder.Build()
    diagram.set_name("drive")
    return diagram, handles, plant.num_actuators(), side
