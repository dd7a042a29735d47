"""What the drive sends for each driver (``hardware.driver_modes``), checked against Drake's own
blocks: the command decoded by ``IiwaCommandReceiver`` and applied by ``SimIiwaDriver`` gives the
arm the controller's torque; ``ptint hardware`` refuses positions that mean something."""

from __future__ import annotations

import numpy as np
import pytest
from drake import lcmt_iiwa_command
from pydrake.manipulation import IiwaCommandReceiver, IiwaControlMode, IiwaDriver, SimIiwaDriver
from pydrake.systems.lcm import _Serializer_

from ptint_drake.hardware.driver_modes import DriverTerms, position_refusal
from ptint_drake.hardware.link import pack_command, unpack_command_positions, utime_of
from ptint_drake.robot.plant import parse_model
from test_lcm_checks import N, pair, tick

MODES = {"torque-gravity": IiwaControlMode.kTorqueOnly, "position-torque": IiwaControlMode.kPositionAndTorque}


def iiwa():
    plant = parse_model("iiwa14")
    plant.Finalize()
    return plant


@pytest.mark.parametrize("mode", sorted(MODES))
def test_drakes_driver_applies_the_controllers_torque(mode):
    """Through Drake's receiver and driver the arm gets τ: the gravity compensation (and, in
    position + torque, the inverse dynamics at zero acceleration) is taken off; at rest the
    position loop adds nothing, as the positions are the measured ones."""
    plant = iiwa()
    n = plant.num_velocities()
    rng = np.random.default_rng(3)
    q, tau = rng.uniform(-1.0, 1.0, n), rng.uniform(-5.0, 5.0, n)
    data = DriverTerms(mode, plant).command(1234, tau, q, np.zeros(n))
    receiver = IiwaCommandReceiver(n, MODES[mode])
    rx = receiver.CreateDefaultContext()
    value = _Serializer_[lcmt_iiwa_command]().CreateDefaultValue()
    _Serializer_[lcmt_iiwa_command]().Deserialize(data, value)
    receiver.get_message_input_port().FixValue(rx, value)
    receiver.get_position_measured_input_port().FixValue(rx, q)
    config = IiwaDriver()
    config.control_mode = "position_and_torque" if mode == "position-torque" else "torque_only"
    driver = SimIiwaDriver(config, plant)
    ctx = driver.CreateDefaultContext()
    driver.GetInputPort("state").FixValue(ctx, np.concatenate([q, np.zeros(n)]))
    driver.GetInputPort("generalized_contact_forces").FixValue(ctx, np.zeros(n))
    driver.GetInputPort("torque").FixValue(ctx, receiver.get_commanded_torque_output_port().Eval(rx))
    if mode == "position-torque":
        driver.GetInputPort("position").FixValue(ctx, receiver.get_commanded_position_output_port().Eval(rx))
    applied = driver.GetOutputPort("actuation").Eval(ctx)
    assert np.allclose(applied, tau, atol=1e-9), applied - tau
    # (the check can fail: what the driver adds at this pose is tens of N·m)
    assert np.linalg.norm(DriverTerms(mode, plant).added(q, np.zeros(n))) > 10.0


def test_commands_carry_the_joint_count_and_positions():
    q, tau = np.array([0.1, 0.2, 0.3]), np.array([1.0, 2.0, 3.0])
    utime, tau2, q2 = unpack_command_positions(pack_command(9, tau, positions=q), 3)
    assert utime == 9 and np.array_equal(tau2, tau) and np.array_equal(q2, q)
    assert lcmt_iiwa_command.decode(pack_command(9, tau, positions=q)).num_joints == 3
    assert unpack_command_positions(pack_command(9, tau), 3)[2] is None


def test_ptint_hardware_takes_echoed_positions_and_refuses_commanded_ones():
    """The torque-only hardware: positions equal to the status's measured ones (what the drive
    sends) are taken; others are a position command, refused in one line, not ignored."""
    session, _ = pair()
    tau = np.array([0.5, -1.0, 2.0])
    out = tick(session, 0.002, [pack_command(utime_of(0.002), tau, positions=np.zeros(N))])
    assert np.array_equal(out, tau) and session.record.fault is None
    moved = np.array([0.0, 0.25, 0.0])
    assert tick(session, 0.003, [pack_command(utime_of(0.003), tau, positions=moved)]) is None
    assert session.record.fault_kind == "bad command"
    assert "a position + torque command (joint 1 commanded 0.25 rad, measured 0 rad)" in session.record.fault
    assert "\n" not in session.record.fault
    assert position_refusal(None, np.zeros(3)) is None


def test_a_stamp_truncated_by_drakes_command_sender_is_the_answer():
    """Drake's ``IiwaCommandSender`` truncates t·10⁶ (1.001 s → 1000999 µs): that command answers
    the status of 1.001 s; a stamp 2 µs short is still no status's."""
    session, _ = pair()
    tau = np.ones(N)
    assert np.array_equal(tick(session, 1.001, [pack_command(1_000_999, tau)]), tau)
    assert session.record.fault is None
    tick(session, 1.002, [pack_command(1_001_998, tau)])
    assert session.record.fault_kind == "second sender"
