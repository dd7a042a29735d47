"""The arm's message set on the link: which Drake LCM types and channels carry the arm's status
and command (``ptint drive --messages``).  The choice belongs to the arm's driver, not to a world:

- ``iiwa`` (the default): ``lcmt_iiwa_status`` on ``IIWA_STATUS``, ``lcmt_iiwa_command`` on
  ``IIWA_COMMAND`` (``link``: every command carries ``num_joints`` = n and the measured
  positions, which a torque-only driver ignores);
- ``panda``: ``lcmt_panda_status`` on ``PANDA_STATUS``, ``lcmt_panda_command`` on
  ``PANDA_COMMAND`` (the default channels of Drake's franka driver and its ``PandaCommandReceiver``
  / ``PandaStatusSender``).  The status gives ``utime``, ``num_joints`` = n, ``joint_position``
  (rad) and ``joint_velocity`` (rad/s).  A command is one control mode: ``control_mode_expected``
  = ``CONTROL_MODE_TORQUE`` with ``num_joint_torque`` = n torques and no positions (Drake's
  receiver wants a vector sized iff its mode bit is set; the franka driver refuses positions in
  torque mode), or ``CONTROL_MODE_POSITION | CONTROL_MODE_TORQUE`` with the measured positions
  too (``position-torque``: a ``PandaCommandReceiver`` built with both bits).  Velocities are
  never sent.

Each set gives the drive its ``unpack_status`` and ``pack_command``, and a station its
``pack_status`` and ``unpack_command_positions`` (the same signatures as ``link``'s iiwa ones).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np
from drake import lcmt_panda_command, lcmt_panda_status

from ptint_drake.hardware import link

PANDA_STATUS_CHANNEL = "PANDA_STATUS"  # the franka driver's default channels
PANDA_COMMAND_CHANNEL = "PANDA_COMMAND"
PANDA_TORQUE = lcmt_panda_status.CONTROL_MODE_TORQUE
PANDA_POSITION = lcmt_panda_status.CONTROL_MODE_POSITION


@dataclass(frozen=True)
class ArmMessages:
    """One message set (module docstring): its name, channels and packers."""

    name: str
    status_channel: str
    command_channel: str
    unpack_status: Callable[[bytes, int], tuple]  # (data, n) -> (utime, q, v)
    pack_command: Callable[..., bytes]  # (utime, tau, positions, with_positions) -> data
    pack_status: Callable[..., bytes]  # (t, q, v, tau) -> data
    unpack_command_positions: Callable[[bytes, int], tuple]  # (data, n) -> (utime, tau, positions)


def _iiwa_command(utime: int, tau: np.ndarray, positions: Optional[np.ndarray],
                  with_positions: bool) -> bytes:
    """``link.pack_command``: the iiwa's command always carries the positions given."""
    return link.pack_command(utime, tau, positions=positions)


def panda_status(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> bytes:
    """An ``lcmt_panda_status`` of the sample at ``t`` (s): q (rad), v (rad/s), τ applied (N·m);
    the desired values are the measured ones, the external torque 0, torque mode."""
    m = lcmt_panda_status()
    n = len(q)
    m.utime = m.robot_utime = link.utime_of(t)
    m.num_joints = n
    m.joint_position = m.joint_position_desired = [float(x) for x in q]
    m.joint_velocity = m.joint_velocity_desired = [float(x) for x in v]
    m.joint_acceleration_desired = [0.0] * n
    m.joint_torque = m.joint_torque_desired = [float(x) for x in tau]
    m.joint_torque_external = [0.0] * n
    m.control_command_success_rate = 1.0
    m.robot_mode = lcmt_panda_status.kMove
    m.control_mode = PANDA_TORQUE
    return m.encode()


def panda_unpack_status(data: bytes, n: int) -> tuple[int, np.ndarray, np.ndarray]:
    """(utime, q, v) of an ``lcmt_panda_status``; ValueError naming what is wrong."""
    return link.decoded_status(lcmt_panda_status, data, n, "joint_position", "joint_velocity")


def panda_command(utime: int, tau: np.ndarray, positions: Optional[np.ndarray],
                  with_positions: bool) -> bytes:
    """An ``lcmt_panda_command`` answering the status of ``utime``: τ (N·m), and with
    ``with_positions`` the ``positions`` (rad) in position + torque mode (module docstring)."""
    m = lcmt_panda_command()
    m.utime = int(utime)
    m.num_joint_torque, m.joint_torque = len(tau), [float(x) for x in tau]
    m.joint_position = [float(x) for x in positions] if with_positions and positions is not None else []
    m.num_joint_position = len(m.joint_position)
    m.num_joint_velocity, m.joint_velocity = 0, []
    m.control_mode_expected = PANDA_TORQUE | (PANDA_POSITION if m.num_joint_position else 0)
    return m.encode()


def panda_unpack_command(data: bytes, n: int) -> tuple[int, np.ndarray, Optional[np.ndarray]]:
    """(utime, τ, positions or None) of an ``lcmt_panda_command`` for ``n`` joints; ValueError
    naming what is wrong (undecodable, no torque mode, velocities, a wrong vector size)."""
    try:
        m = lcmt_panda_command.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable command message ({type(exc).__name__})") from None
    if not m.control_mode_expected & PANDA_TORQUE:
        raise ValueError(f"a command in control mode {m.control_mode_expected} without the torque bit "
                         f"({PANDA_TORQUE}): ptint hardware applies torques")
    if m.num_joint_velocity:
        raise ValueError(f"a command of {m.num_joint_velocity} velocities: ptint hardware applies torques")
    if m.num_joint_torque != n or len(m.joint_torque) != n:
        raise ValueError(f"a command of {m.num_joint_torque} torques, the arm has {n} joints")
    if m.num_joint_position not in (0, n):
        raise ValueError(f"a command of {m.num_joint_position} positions (0 or {n})")
    positions = np.array(m.joint_position, dtype=float) if m.num_joint_position else None
    return m.utime, np.array(m.joint_torque, dtype=float), positions


IIWA = ArmMessages("iiwa", link.STATUS_CHANNEL, link.COMMAND_CHANNEL, link.unpack_status, _iiwa_command,
                   link.pack_status, link.unpack_command_positions)
PANDA = ArmMessages("panda", PANDA_STATUS_CHANNEL, PANDA_COMMAND_CHANNEL, panda_unpack_status, panda_command,
                    panda_status, panda_unpack_command)
MESSAGES = {m.name: m for m in (IIWA, PANDA)}


def arm_messages(name: str) -> ArmMessages:
    """The message set called ``name``; ValueError naming the choices."""
    if name not in MESSAGES:
        raise ValueError(f"--messages: {name!r} is not one of {', '.join(MESSAGES)}")
    return MESSAGES[name]
