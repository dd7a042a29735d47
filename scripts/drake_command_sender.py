"""Drake's ``IiwaCommandSender`` driving ``ptint hardware`` (issue 45: Drake's drivers, the other
direction): a controller built of Drake's blocks alone — ``IiwaStatusReceiver`` → an
``InverseDynamicsController`` holding the start pose (kp 100/s², kd 20/s, the arm's model file
parsed by Drake) → ``IiwaCommandSender`` — answering each ``lcmt_iiwa_status`` on IIWA_STATUS
with its ``lcmt_iiwa_command`` on IIWA_COMMAND, the sender's time input fed from the receiver's
``time_measured``, as a Drake diagram wires them.

``--mode torque_only``: torques alone (num_joints 0): ``ptint hardware`` applies them.
``--mode position_and_torque``: the start pose as positions beside the torques: ``ptint
hardware``, a torque-only driver, refuses them in one line at the first command whose positions
are not the measured ones.

    python scripts/drake_command_sender.py curve_iiwa14 --mode torque_only   # beside
    ptint hardware curve_iiwa14 --lockstep

It answers until no status came for ``--idle`` s (1) after the first, and prints the commands
sent.  Exit 0, or 2 on bad input (one line).
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np
from drake import lcmt_iiwa_command, lcmt_iiwa_status
from pydrake.lcm import DrakeLcm
from pydrake.manipulation import IiwaCommandSender, IiwaStatusReceiver, ParseIiwaControlMode
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.controllers import InverseDynamicsController
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.lcm import _Serializer_
from pydrake.systems.primitives import ConstantVectorSource, Multiplexer

from ptint_drake.config.errors import ScenarioError
from ptint_drake.robot.plant import resolve_model
from ptint_drake.simulation.scenario import LoadedScenario

MODES = ("torque_only", "position_and_torque")
KP, KD = 100.0, 20.0  # 1/s², 1/s: the hold's gains (inverse dynamics: accelerations)


def build_controller(model_file: str, q0: np.ndarray, mode: str):
    """(diagram, its plant) of receiver → inverse-dynamics hold of ``q0`` → sender."""
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(model_file)
    plant.Finalize()
    n = plant.num_positions()
    builder = DiagramBuilder()
    receiver = builder.AddSystem(IiwaStatusReceiver(n))
    state = builder.AddSystem(Multiplexer([n, n]))
    hold = builder.AddSystem(
        InverseDynamicsController(plant, np.full(n, KP), np.zeros(n), np.full(n, KD), False))
    desired = builder.AddSystem(ConstantVectorSource(np.concatenate([q0, np.zeros(n)])))
    sender = builder.AddSystem(IiwaCommandSender(n, ParseIiwaControlMode(mode)))
    builder.Connect(receiver.GetOutputPort("position_measured"), state.get_input_port(0))
    builder.Connect(receiver.GetOutputPort("velocity_estimated"), state.get_input_port(1))
    builder.Connect(state.get_output_port(), hold.get_input_port_estimated_state())
    builder.Connect(desired.get_output_port(), hold.get_input_port_desired_state())
    builder.Connect(hold.get_output_port_control(), sender.get_torque_input_port())
    builder.Connect(receiver.GetOutputPort("time_measured"), sender.get_time_input_port())
    if mode == "position_and_torque":
        start = builder.AddSystem(ConstantVectorSource(q0))
        builder.Connect(start.get_output_port(), sender.get_position_input_port())
    builder.ExportInput(receiver.get_input_port(), "status")
    builder.ExportOutput(sender.get_output_port(), "command")
    return builder.Build(), plant


def answer(diagram, url, idle: float, startup: float) -> int:
    """Answer each status until ``idle`` s without one (``startup`` s before the first); the
    number of commands sent."""
    lcm = DrakeLcm(url) if url else DrakeLcm()
    inbox: list[bytes] = []
    lcm.Subscribe("IIWA_STATUS", lambda data: inbox.append(bytes(data)))
    status_ser, command_ser = _Serializer_[lcmt_iiwa_status](), _Serializer_[lcmt_iiwa_command]()
    status = status_ser.CreateDefaultValue()
    context = diagram.CreateDefaultContext()
    port_in, port_out = diagram.GetInputPort("status"), diagram.GetOutputPort("command")
    sent, last = 0, time.monotonic()
    while time.monotonic() - last < (idle if sent else startup):
        lcm.HandleSubscriptions(10)
        for data in inbox:
            status_ser.Deserialize(data, status)
            port_in.FixValue(context, status)
            lcm.Publish("IIWA_COMMAND", command_ser.Serialize(port_out.EvalAbstract(context)))
            sent, last = sent + 1, time.monotonic()
        inbox.clear()
    return sent


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenario")
    p.add_argument("--mode", choices=MODES, default="torque_only")
    p.add_argument("--url")
    p.add_argument("--idle", type=float, default=1.0)
    p.add_argument("--startup-timeout", type=float, default=60.0)
    p.add_argument("--set", action="append", metavar="KEY=VALUE")
    args = p.parse_args(argv)
    try:
        scenario = LoadedScenario.load(args.scenario, args.set or ()).scenario
        model_file = str(resolve_model(scenario.robot.model))
    except ScenarioError as exc:
        print(f"drake_command_sender: error: {exc}", file=sys.stderr)
        return 2
    diagram, _ = build_controller(model_file, np.radians(scenario.robot.initial_q_deg), args.mode)
    sent = answer(diagram, args.url, args.idle, args.startup_timeout)
    print(f"drake_command_sender {args.mode}: sent {sent} commands")
    return 0


if __name__ == "__main__":
    sys.exit(main())
