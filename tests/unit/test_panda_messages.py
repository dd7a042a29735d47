"""The Panda's messages (``hardware.arm_messages``) against Drake's own Panda blocks: what the
drive sends, decoded by ``PandaCommandReceiver`` and applied by ``SimIiwaDriver`` (the station's
driver: ``scripts/drake_blocks_station.py``), gives the arm the controller's torque; a torque
command carries no positions (Drake's receiver and the franka driver want none); what
``PandaStatusSender`` publishes is read as the arm's state; bad commands are named in one line."""

from __future__ import annotations

import numpy as np
import pytest
from drake import lcmt_panda_command, lcmt_panda_status
from pydrake.manipulation import IiwaDriver, PandaCommandReceiver, PandaControlMode, PandaStatusSender
from pydrake.manipulation import SimIiwaDriver
from pydrake.systems.lcm import _Serializer_

from ptint_drake.hardware.arm_messages import (IIWA, PANDA, arm_messages, panda_command, panda_status,
                                               panda_unpack_command)
from ptint_drake.hardware.driver_modes import DriverTerms
from ptint_drake.robot.plant import parse_model

TORQUE, POSITION = int(PandaControlMode.kTorque), int(PandaControlMode.kPosition)
RECEIVER_MODE = {"torque-gravity": TORQUE, "position-torque": TORQUE | POSITION}


def panda():
    plant = parse_model("panda")
    plant.Finalize()
    return plant


def received(receiver: PandaCommandReceiver, data: bytes, q: np.ndarray):
    """(receiver context) with ``data`` decoded on its message port and ``q`` measured."""
    context = receiver.CreateDefaultContext()
    value = _Serializer_[lcmt_panda_command]().CreateDefaultValue()
    _Serializer_[lcmt_panda_command]().Deserialize(data, value)
    receiver.get_message_input_port().FixValue(context, value)
    receiver.get_position_measured_input_port().FixValue(context, q)
    return context


@pytest.mark.parametrize("mode", sorted(RECEIVER_MODE))
def test_drakes_panda_receiver_gives_the_arm_the_controllers_torque(mode):
    plant = panda()
    n = plant.num_velocities()
    rng = np.random.default_rng(5)
    q, tau = rng.uniform(-1.0, 1.0, n), rng.uniform(-5.0, 5.0, n)
    # moving in torque mode (gravity does not depend on v); at rest in position + torque, where
    # the driver also damps the difference between its velocity estimate and the arm's
    v = rng.uniform(-0.5, 0.5, n) if mode == "torque-gravity" else np.zeros(n)
    data = DriverTerms(mode, plant, PANDA).command(4321, tau, q, v)
    message = lcmt_panda_command.decode(data)
    assert message.utime == 4321 and message.num_joint_velocity == 0
    if mode == "torque-gravity":  # one mode, no positions: what the franka driver's torque mode takes
        assert message.control_mode_expected == lcmt_panda_status.CONTROL_MODE_TORQUE
        assert message.num_joint_position == 0
    receiver = PandaCommandReceiver(n, RECEIVER_MODE[mode])
    rx = received(receiver, data, q)
    config = IiwaDriver()
    config.control_mode = "position_and_torque" if mode == "position-torque" else "torque_only"
    driver = SimIiwaDriver(config, plant)
    ctx = driver.CreateDefaultContext()
    driver.GetInputPort("state").FixValue(ctx, np.concatenate([q, v]))
    driver.GetInputPort("generalized_contact_forces").FixValue(ctx, np.zeros(n))
    driver.GetInputPort("torque").FixValue(ctx, receiver.get_commanded_torque_output_port().Eval(rx))
    if mode == "position-torque":
        positions = receiver.get_commanded_position_output_port().Eval(rx)
        assert np.array_equal(positions, q)  # the measured positions: no position error
        driver.GetInputPort("position").FixValue(ctx, positions)
    applied = driver.GetOutputPort("actuation").Eval(ctx)
    assert np.allclose(applied, tau, atol=1e-9), applied - tau
    # (the check can fail: what the driver adds at this state is tens of N·m)
    assert np.linalg.norm(DriverTerms(mode, plant, PANDA).added(q, v)) > 10.0

def test_a_torque_command_into_a_position_and_torque_receiver_is_refused_by_drake():
    """Drake's receiver checks the command's mode against its own: the drive's --driver-mode
    must match the station's (a mismatch aborts the station: docs/hardware.md)."""
    plant = panda()
    n = plant.num_velocities()
    data = panda_command(7, np.ones(n), np.zeros(n), with_positions=False)
    receiver = PandaCommandReceiver(n, TORQUE | POSITION)
    with pytest.raises((RuntimeError, SystemExit), match="control_mode_expected"):  # (a Drake abort)
        receiver.get_commanded_position_output_port().Eval(received(receiver, data, np.zeros(n)))


def test_drakes_panda_status_is_read_as_the_arms_state():
    n = 7
    sender = PandaStatusSender(n)
    ctx = sender.CreateDefaultContext()
    q, v, tau = np.linspace(-1, 1, n), np.linspace(0.1, 0.7, n), np.linspace(-3, 3, n)
    sender.get_position_measured_input_port().FixValue(ctx, q)
    sender.get_velocity_measured_input_port().FixValue(ctx, v)
    sender.get_torque_commanded_input_port().FixValue(ctx, tau)
    ctx.SetTime(1.25)
    data = _Serializer_[lcmt_panda_status]().Serialize(sender.get_output_port().EvalAbstract(ctx))
    utime, q2, v2 = PANDA.unpack_status(data, n)
    assert utime == 1_250_000 and np.array_equal(q2, q) and np.array_equal(v2, v)
    with pytest.raises(ValueError, match="a status of 7 joints, the scenario's arm has 6"):
        PANDA.unpack_status(data, 6)
    # ptint's own status (a station of ptint's speaking Panda) reads back the same way
    utime, q3, v3 = PANDA.unpack_status(panda_status(1.25, q, v, tau), n)
    assert utime == 1_250_000 and np.array_equal(q3, q) and np.array_equal(v3, v)


def test_panda_commands_unpacked_or_named_in_one_line():
    tau, q = np.array([1.0, -2.0, 3.0]), np.array([0.1, 0.2, 0.3])
    assert panda_unpack_command(panda_command(9, tau, q, with_positions=False), 3)[2] is None
    utime, tau2, q2 = panda_unpack_command(panda_command(9, tau, q, with_positions=True), 3)
    assert utime == 9 and np.array_equal(tau2, tau) and np.array_equal(q2, q)
    velocity = lcmt_panda_command()
    velocity.control_mode_expected = lcmt_panda_status.CONTROL_MODE_VELOCITY
    velocity.num_joint_velocity, velocity.joint_velocity = 3, [0.0] * 3
    for data, says in [
        (velocity.encode(), "without the torque bit"),
        (panda_command(9, tau[:2], None, with_positions=False), "a command of 2 torques, the arm has 3"),
        (b"junk", "an undecodable command message"),
    ]:
        with pytest.raises(ValueError, match=says) as err:
            panda_unpack_command(data, 3)
        assert "\n" not in str(err.value)


def test_the_sets_by_name():
    assert arm_messages("iiwa") is IIWA and arm_messages("panda").status_channel == "PANDA_STATUS"
    with pytest.raises(ValueError, match="--messages: 'ur' is not one of iiwa, panda"):
        arm_messages("ur")


def test_ptint_hardware_and_drive_over_panda_messages_as_over_the_iiwas(tmp_path):
    """``ptint hardware --messages panda`` and ``ptint drive --messages panda`` (two threads over
    one ``memq://`` LCM, lockstep): the arm moves bit for bit as over the iiwa's messages, on the
    Panda's channels."""
    from ptint_drake.hardware.in_memory import run_pair  # noqa: PLC0415
    from ptint_drake.hardware.session import LinkSettings  # noqa: PLC0415
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415

    short = ["duration=0.3", "interceptions[0].tf=0.25", "controller.control_period=0.001",
             "multibody.time_step=0.001"]
    scenario = parse_with_overrides(scenario_text("curve_panda")[1], short, "curve_panda")
    finals = {}
    for messages in ("iiwa", "panda"):
        settings = LinkSettings(period=0.001, duration=0.3, messages=messages)
        metrics, drive = run_pair(scenario, settings, tmp_path / messages)
        link = metrics["hardware"]
        assert link["fault"] is None and link["ticks"] == 300 and drive["commands_sent"] >= 300
        assert link["command_channel"] == drive["command_channel"] == arm_messages(messages).command_channel
        series = np.load(tmp_path / messages / "series.npz")
        finals[messages] = series["x"][-1]
    assert np.array_equal(finals["iiwa"], finals["panda"])
    assert np.linalg.norm(finals["panda"] - series["x"][0]) > 1e-3  # (the arm moved: the check can fail)
