"""A station built of Drake's own iiwa blocks on LCM, for ``ptint drive`` (issue 45: Drake's
drivers, both directions): a discrete ``MultibodyPlant`` of the scenario's arm (its model file,
parsed by Drake), ``IiwaCommandReceiver`` → ``SimIiwaDriver`` (``IiwaDriver`` config: its
``control_mode``; ``desired_kp_gains`` for an arm of other than 7 joints) → the plant, and
``IiwaStatusSender``; no ptint code in the loop.

The harness runs it in lockstep: at each status period it publishes the sender's
``lcmt_iiwa_status`` on IIWA_STATUS (re-sent every 5 ms until answered), waits for the
``lcmt_iiwa_command`` on IIWA_COMMAND that carries that status's stamp (others are counted and
dropped), hands it to the receiver, and advances the diagram one status period.  It then measures
the scenario's segments from the statuses it sent (the tool point from the plant's kinematics
against the scenario's true target) and writes station.json::

    python scripts/drake_blocks_station.py curve_iiwa14 --mode torque_only --out /tmp/st
    ptint drive curve_iiwa14 --driver-mode torque-gravity          # in another shell

``--mode``: ``torque_only`` (``SimIiwaDriver`` adds gravity compensation: drive with
``--driver-mode torque-gravity``) or ``position_and_torque`` (Drake's default: ``--driver-mode
position-torque``).  ``--status-period`` (s, 0.001; Drake's iiwa: 0.005) and ``--plant-step``
(s, 0.001).  Exit 0 when every segment meets the scenario's criteria, 1 otherwise or when no
command came in time, 2 on bad input (one line).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numpy as np
from drake import lcmt_iiwa_command, lcmt_iiwa_status
from pydrake.lcm import DrakeLcm
from pydrake.manipulation import IiwaCommandReceiver, IiwaDriver, IiwaStatusSender, ParseIiwaControlMode
from pydrake.manipulation import SimIiwaDriver
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlant, MultibodyPlantConfig
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.lcm import _Serializer_

from ptint_drake.config.errors import ScenarioError
from ptint_drake.verdict.metrics import segment_metrics, segment_reasons
from ptint_drake.robot.plant import resolve_model
from ptint_drake.simulation.scenario import LoadedScenario
from ptint_drake.worlds.registry import objects_of, schedule_of

STATUS, COMMAND = "IIWA_STATUS", "IIWA_COMMAND"
IIWA_KP = (2000.0, 1500.0, 1500.0, 1500.0, 1500.0, 500.0, 500.0)  # SimIiwaDriver's default gains
RESEND = 0.005  # s wall between re-sends of an unanswered status
MODES = ("torque_only", "position_and_torque")


def arm_plant(model_file: str, time_step: float, builder=None):
    """The arm's model file parsed by Drake into a plant (with a scene graph on ``builder``)."""
    if builder is None:
        plant = MultibodyPlant(time_step)
    else:
        plant, _ = AddMultibodyPlant(MultibodyPlantConfig(time_step=time_step), builder)
    Parser(plant).AddModels(model_file)
    plant.Finalize()
    return plant


def build_station(model_file: str, mode: str, plant_step: float):
    """(diagram, plant, the controller plant, receiver, sender) of the station (module docstring)."""
    builder = DiagramBuilder()
    plant = arm_plant(model_file, plant_step, builder)
    controller_plant = arm_plant(model_file, 0.0)
    n = plant.num_positions()
    config = IiwaDriver()
    config.control_mode = mode
    if n != len(IIWA_KP):  # Drake's default gains are the 7-joint iiwa's
        config.desired_kp_gains = np.resize(np.array(IIWA_KP), n)
    instance = plant.get_joint_actuator(plant.GetJointActuatorIndices()[0]).joint().model_instance()
    driver = SimIiwaDriver.AddToBuilder(builder, plant, instance, config, controller_plant)
    receiver = builder.AddSystem(IiwaCommandReceiver(n, ParseIiwaControlMode(mode)))
    sender = builder.AddSystem(IiwaStatusSender(n))
    builder.Connect(driver.GetOutputPort("position_measured"), receiver.get_position_measured_input_port())
    builder.Connect(receiver.get_commanded_torque_output_port(), driver.GetInputPort("torque"))
    if mode == "position_and_torque":
        builder.Connect(receiver.get_commanded_position_output_port(), driver.GetInputPort("position"))
    for port in ("position_commanded", "position_measured", "velocity_estimated", "torque_commanded",
                 "torque_measured", "torque_external"):
        builder.Connect(driver.GetOutputPort(port), sender.GetInputPort(port))
    builder.ExportInput(receiver.get_message_input_port(), "command")
    builder.ExportOutput(sender.get_output_port(), "status")
    return builder.Build(), plant, controller_plant, receiver, sender


class Lockstep:
    """The harness: one status period at a time, each waiting for the command with its stamp."""

    def __init__(self, diagram, url, command_timeout: float, startup_timeout: float):
        self.lcm = DrakeLcm(url) if url else DrakeLcm()
        self.inbox: list[bytes] = []
        self.lcm.Subscribe(COMMAND, lambda data: self.inbox.append(bytes(data)))
        self.status_ser = _Serializer_[lcmt_iiwa_status]()
        self.command_ser = _Serializer_[lcmt_iiwa_command]()
        self.command = self.command_ser.CreateDefaultValue()
        self.diagram, self.simulator = diagram, Simulator(diagram)
        self.context = self.simulator.get_mutable_context()
        self.command_in = diagram.GetInputPort("command")
        self.command_in.FixValue(self.context, self.command)
        self.timeouts = (startup_timeout, command_timeout)
        self.resends = self.others = 0

    def tick(self, first: bool) -> int:
        """Publish the status of the current time, take the command with its stamp (returns the
        stamp); TimeoutError when none came in time."""
        data = self.status_ser.Serialize(self.diagram.GetOutputPort("status").EvalAbstract(self.context))
        stamp = lcmt_iiwa_status.decode(data).utime
        wait = self.timeouts[0 if first else 1]
        deadline = time.monotonic() + wait
        sent = time.monotonic()
        self.lcm.Publish(STATUS, data)
        while True:
            self.lcm.HandleSubscriptions(1)
            for message in self.inbox:
                if lcmt_iiwa_command.decode(message).utime == stamp:
                    self.inbox.clear()
                    self.command_ser.Deserialize(message, self.command)
                    self.command_in.FixValue(self.context, self.command)
                    return stamp
                self.others += 1
            self.inbox.clear()
            now = time.monotonic()
            if now > deadline:
                raise TimeoutError(f"no command stamped {stamp} within {wait:g} s")
            if now - sent >= RESEND:
                self.resends += 1
                sent = now
                self.lcm.Publish(STATUS, data)


def tool_motion(plant, frame_name: str, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, ẋ) of the tool frame's origin at (q, v) (world frame)."""
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    frame, world = plant.GetFrameByName(frame_name), plant.world_frame()
    x = plant.CalcPointsPositions(context, frame, np.zeros(3), world).ravel()
    J = plant.CalcJacobianTranslationalVelocity(
        context, JacobianWrtVariable.kV, frame, np.zeros(3), world, world)
    return x, J @ v


def measure(scenario, plant, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> list[dict]:
    """The scenario's segment metrics and reasons from the statuses (true target, exact times)."""
    schedule, objects = schedule_of(scenario), objects_of(scenario)
    xs, objs, samples = [], [], {}
    for k, tk in enumerate(t):
        x, xdot = tool_motion(plant, scenario.robot.end_effector, q[k], v[k])
        targets = [o.evaluate(tk) for o in objects]
        xs.append(x)
        objs.append(np.concatenate([r[:3] for r in targets]))
        for i, seg in enumerate(schedule.segments):
            for at in (seg.start, seg.start + 0.5 * seg.tf, seg.end):
                if abs(tk - at) < 1e-9:
                    samples[at] = (x - targets[i][:3], xdot - targets[i][3:6])
    rows = segment_metrics(schedule, scenario.duration, samples, t, np.array(xs), np.array(objs))
    for row in rows:
        row["reasons"] = segment_reasons(row, scenario.criteria)
    return rows


def run(args: argparse.Namespace) -> dict:
    """Build, run in lockstep and measure (module docstring); station.json's content."""
    scenario = LoadedScenario.load(args.scenario, args.set or ()).scenario
    model_file = str(resolve_model(scenario.robot.model))
    diagram, plant, _, _, _ = build_station(model_file, args.mode, args.plant_step)
    loop = Lockstep(diagram, args.url, args.command_timeout, args.startup_timeout)
    plant_context = plant.GetMyMutableContextFromRoot(loop.context)
    plant.SetPositions(plant_context, np.radians(scenario.robot.initial_q_deg))
    loop.simulator.Initialize()  # (after the start pose: the receiver and the driver latch it)
    ticks = int(round(scenario.duration / args.status_period))
    t, q, v, fault = [], [], [], None
    wall = time.monotonic()
    for k in range(ticks):
        state = plant.GetPositionsAndVelocities(plant_context).copy()
        try:
            loop.tick(first=k == 0)
        except TimeoutError as exc:
            fault = f"t = {k * args.status_period:.3f} s: {exc}"
            break
        t.append(k * args.status_period)
        q.append(state[: plant.num_positions()])
        v.append(state[plant.num_positions():])
        loop.simulator.AdvanceTo((k + 1) * args.status_period)
    segments = measure(scenario, plant, np.array(t), np.array(q), np.array(v)) if t else []
    ok = fault is None and all(not s["reasons"] for s in segments)
    return {"scenario": scenario.name, "mode": args.mode, "status_period": args.status_period,
            "plant_step": args.plant_step, "ticks": len(t), "status_resends": loop.resends,
            "other_commands": loop.others, "wall_s": time.monotonic() - wall, "fault": fault,
            "segments": segments, "status": "ok" if ok else "missed" if fault is None else "failed"}


def parse(argv) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scenario")
    p.add_argument("--mode", choices=MODES, default="torque_only")
    p.add_argument("--status-period", type=float, default=0.001)
    p.add_argument("--plant-step", type=float, default=0.001)
    p.add_argument("--command-timeout", type=float, default=5.0)
    p.add_argument("--startup-timeout", type=float, default=60.0)
    p.add_argument("--url")
    p.add_argument("--set", action="append", metavar="KEY=VALUE")
    p.add_argument("--out", default="out/drake_blocks_station")
    args = p.parse_args(argv)
    for name in ("status_period", "plant_step", "command_timeout", "startup_timeout"):
        if not getattr(args, name) > 0:
            p.exit(2, f"drake_blocks_station: error: --{name.replace('_', '-')}: must be > 0\n")
    return args


def main(argv=None) -> int:
    args = parse(argv)
    try:
        result = run(args)
    except ScenarioError as exc:
        print(f"drake_blocks_station: error: {exc}", file=sys.stderr)
        return 2
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "station.json").write_text(json.dumps(result, indent=1))
    for i, seg in enumerate(result["segments"]):
        e = seg["e_tf_norm"]
        print(f"segment {i}: e(tf) = {e * 1e3:.4f} mm" if e is not None else f"segment {i}: not reached",
              f"hold max = {seg['e_hold_max_norm'] * 1e3:.4f} mm" if seg["e_hold_max_norm"] else "",
              ", ".join(seg["reasons"]) or "ok")
    print(f"station {result['mode']}, status {result['status_period'] * 1e3:g} ms: {result['status']}"
          + (f" ({result['fault']})" if result["fault"] else "") + f"; wrote {out}/station.json")
    return 0 if result["status"] == "ok" else 1


if __name__ == "__main__":
    sys.exit(main())
