"""A hold experiment on the pick station: the arm held still by a joint PD on its ``actuation``
and ``state`` ports, the belts running, part 0 put between the pads and the gripper closed on
it — what ``scripts/contact_bench.py`` measures per contact approximation and the tests check.

``measure_hold`` returns (units in the keys): the realtime factor of the simulated span; the
held part's largest displacement relative to the fingertip frame (``held_drift_mm``, from the
end of the ``settle`` time, when the grip is established); the largest belt-following error of
the other parts (``belt_speed_error_pct``: |v_part − v_belt| / v_belt along the belt, sampled
every 0.1 s after ``settle``); the grip force at the end (``grip_force_N``, per finger).
"""

from __future__ import annotations

import time

import numpy as np
from pydrake.systems.controllers import PidController
from pydrake.systems.framework import Diagram, DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.worlds.base import new_simulator
from ptint_drake.worlds.pick.config import PickWorldConfig
from ptint_drake.worlds.pick.station import MakePickStation, PickStation

ARM_KP, ARM_KD = 100.0, 5.0  # N·m/rad, N·m·s/rad: the holding PD (explicit: kd·dt/I stays ≪ 2)


def MakeHoldingDiagram(config: PickWorldConfig, command: float = 0.0) -> tuple[Diagram, PickStation]:
    """The station with the arm's joint PD to ``initial_q_deg`` and a constant gripper command."""
    station = MakePickStation(config)
    builder = DiagramBuilder()
    world = builder.AddNamedSystem("station", station.diagram)
    n = station.plant.num_velocities(station.arm)
    pid = builder.AddNamedSystem("arm_pd", PidController(np.full(n, ARM_KP), np.zeros(n), np.full(n, ARM_KD)))
    q0 = np.radians(config.initial_q_deg)
    desired = builder.AddNamedSystem("arm_hold", ConstantVectorSource(np.concatenate([q0, np.zeros(n)])))
    grip = builder.AddNamedSystem("command", ConstantVectorSource([command]))
    builder.Connect(world.GetOutputPort("state"), pid.get_input_port_estimated_state())
    builder.Connect(desired.get_output_port(), pid.get_input_port_desired_state())
    builder.Connect(pid.get_output_port_control(), world.GetInputPort("actuation"))
    builder.Connect(grip.get_output_port(), world.GetInputPort("gripper_command"))
    return builder.Build(), station


def measure_hold(config: PickWorldConfig, duration: float = 2.0, settle: float = 0.1) -> dict:
    """Runs the hold experiment (part 0 held, the others on their belts); the numbers above."""
    diagram, station = MakeHoldingDiagram(config)
    context = diagram.CreateDefaultContext()
    plant, pc = station.plant, station.plant.GetMyContextFromRoot(context)
    station.start_running(pc)
    station.put_in_hand(pc, 0)
    tip = plant.GetFrameByName("fingertip_center", station.gripper)

    def relative():
        X_WT = tip.CalcPoseInWorld(pc)
        return X_WT.inverse().multiply(plant.EvalBodyPoseInWorld(pc, station.parts[0])).translation()

    simulator = new_simulator(diagram, context)
    simulator.AdvanceTo(settle)
    start, drift, belt_error = relative(), 0.0, 0.0
    belts = {b.name: b for b in config.belts}
    wall = time.perf_counter()
    for t in np.arange(1, round(duration / 0.1) + 1) * 0.1 + settle:
        simulator.AdvanceTo(t)
        drift = max(drift, float(np.linalg.norm(relative() - start)))
        for body, part in list(zip(station.parts, config.parts))[1:]:
            belt = belts[part.belt]
            v = plant.EvalBodySpatialVelocityInWorld(pc, body).translational() @ np.asarray(belt.direction)
            belt_error = max(belt_error, abs(v - belt.speed) / abs(belt.speed))
    wall = time.perf_counter() - wall
    force = station.diagram.GetOutputPort("grip_force").Eval(station.diagram.GetMyContextFromRoot(context))
    return {"realtime_factor": duration / wall, "held_drift_mm": 1e3 * drift,
            "belt_speed_error_pct": 100.0 * belt_error, "grip_force_N": [float(f) for f in force]}
