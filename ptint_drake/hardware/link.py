"""The LCM side both processes share: the URL and its risk, the channels, Drake's ``lcmt_iiwa_*``
messages packed for an arm of any joint count, a subscription inbox, and timing summaries.

The messages are Drake's own (the ``drake`` Python package that ships with pydrake):

- ``lcmt_iiwa_status`` (hardware → drive, channel ``IIWA_STATUS``): ``utime`` = the simulated
  (or the robot's) time of the sample in µs, ``num_joints`` = n, ``joint_position_measured`` (rad),
  ``joint_velocity_estimated`` (rad/s), ``joint_torque_measured`` and ``joint_torque_commanded``
  (N·m: the torque the drive applies over this period), ``joint_position_commanded`` /
  ``joint_position_ipo`` = the measured position (torque-only: nothing else is commanded),
  ``joint_torque_external`` = 0 (not estimated).
- ``lcmt_iiwa_command`` (drive → hardware, channel ``IIWA_COMMAND``): ``utime`` = the ``utime`` of
  the status it answers, ``num_joints`` = n with the status's measured positions (rad; what a
  position + torque driver gets: ``driver_modes``), ``num_torques`` = n, ``joint_torque`` (N·m, in
  the plant's actuator order).

A station with a gripper (``worlds.base.LinkPorts``) adds Drake's gripper messages and, where the
station tracks its objects with a pose tracker, the tracker's reports:

- ``lcmt_schunk_wsg_status`` (hardware → drive, channel ``SCHUNK_WSG_STATUS``, Drake's
  ``hardware_sim`` name), one per tick, before the arm's status: ``utime`` as the arm's,
  ``actual_position_mm`` = the opening between the pads (mm), ``actual_speed_mm_per_s`` = the faster
  finger's speed (mm/s, ≥ 0: what ``systems.hand.gripper.GraspObserver`` takes as the fingers' speed),
  ``actual_force`` = the grip force, the smaller squeeze of the two finger drives (N, + squeezing).
- ``lcmt_schunk_wsg_command`` (drive → hardware, ``SCHUNK_WSG_COMMAND``), one per status, before the
  arm's command: ``utime`` = the tick at which the gripper's driver takes it (the answered status's
  ``utime`` + T; the hand-shake's: 0), ``target_position_mm`` = the wanted opening (mm; 0 = close),
  ``force`` = the grip force limit (N).
- ``lcmt_scope`` (hardware → drive, ``TRACKED_POSES``), one per tick, before the arm's status:
  ``utime`` as the arm's; ``value`` = the station's ``tracked_poses`` port, the pose tracker's
  report: per tracked body (the station's order) [p, v, R row-major, ω] (m, m/s, rad/s; world
  frame), ``TRACKED_SIZE`` doubles a body.  A sensor's output, as a cell's tracker sends it: no
  station's truth port (a body's simulated motion, its accelerations) is on the wire.  Drake has
  no message of a tracked body's pose and twist (``lcmt_viewer_draw`` carries float poses
  without velocities); ``lcmt_scope`` is its plain vector of doubles.

LCM carries no sender identity and no authentication: the default URL stays on this machine
(``ttl=0``) and ``url_warning`` names the risk of any other; the hardware side's checks
(``session``) accept one command per status it sent.
"""

from __future__ import annotations

import contextlib
import socket
import struct
import threading
import time
import urllib.parse
from typing import Optional

import numpy as np
from drake import (lcmt_iiwa_command, lcmt_iiwa_status, lcmt_schunk_wsg_command, lcmt_schunk_wsg_status,
                   lcmt_scope)
from pydrake.lcm import DrakeLcm

from ptint_drake.hardware.process import new_threads, thread_ids
from ptint_drake.worlds.base import TRACKED_SIZE

STATUS_CHANNEL = "IIWA_STATUS"  # Drake's iiwa driver's channel names
COMMAND_CHANNEL = "IIWA_COMMAND"
WSG_STATUS_CHANNEL = "SCHUNK_WSG_STATUS"  # Drake's hardware_sim names
WSG_COMMAND_CHANNEL = "SCHUNK_WSG_COMMAND"
TRACKER_CHANNEL = "TRACKED_POSES"  # a pose tracker's reports (``worlds.base.LinkPorts``)
MEMQ_NAP = 5e-5  # s: a memq:// wait's sleep between two non-blocking handles
# one thread at a time in a memq:// LCM shared by two threads (``in_memory``): pydrake's calls keep
# Python's interpreter lock while LCM takes its own, and LCM calls back into Python
MEMQ_LOCK = threading.Lock()


def url_warning(url: str) -> Optional[str]:
    """A warning for an LCM URL whose packets may leave this machine, or None (``udpm`` with
    ``ttl=0``, or ``memq``)."""
    parsed = urllib.parse.urlparse(url)
    if parsed.scheme == "memq":
        return None
    ttl = urllib.parse.parse_qs(parsed.query).get("ttl", [None])[0]
    if parsed.scheme == "udpm" and ttl is not None and ttl.strip() == "0":
        return None
    told = "no ttl" if ttl is None else f"ttl={ttl}"
    return (
        f"LCM URL {url} has {told}: status and commands may be sent beyond this machine, and LCM has "
        f"no authentication, so anyone on that network can read the arm's state and publish "
        f"commands on its channel; use ?ttl=0 (host-only) unless the network is the robot's own"
    )


class Endpoint:
    """One ``DrakeLcm`` (``url``, or ``LCM_DEFAULT_URL`` / Drake's default when None; or ``lcm``,
    shared: two endpoints on one ``memq://`` instance talk inside one process), publishing on one
    channel and collecting another's messages with their arrival times (``inbox``)."""

    def __init__(
        self, url: Optional[str], listen: str, publish: str, lcm: Optional[DrakeLcm] = None, also: tuple = ()
    ):
        before = thread_ids()
        self.lcm = lcm if lcm is not None else DrakeLcm(url) if url else DrakeLcm()
        self.url = self.lcm.get_lcm_url()
        self._guard = MEMQ_LOCK if self.url.startswith("memq") else contextlib.nullcontext()
        self.listen, self.publish_channel = listen, publish
        self.inbox: list[tuple[float, bytes]] = []
        self.lcm.Subscribe(listen, lambda data: self.inbox.append((time.perf_counter(), bytes(data))))
        # the other channels listened to (``also``: the station's companions), each its own inbox
        self.side: dict[str, list] = {c: [] for c in also}
        for channel in also:
            self.lcm.Subscribe(channel, lambda data, c=channel: self.side[c].append(bytes(data)))
        # the threads LCM started for this endpoint (``udpm``: its receive thread, through which
        # every message passes; none for a shared or ``memq`` LCM): scheduled with the loop's own
        # (``process.request_realtime``)
        self.threads = new_threads(before) if lcm is None else []

    def pump(self, timeout_s: float) -> None:
        """Handle what arrives within ``timeout_s`` into the inboxes (none drained here)."""
        if self.url.startswith("memq"):
            if self._handle() == 0:
                time.sleep(MEMQ_NAP)
        else:
            self._handle(max(0, int(round(timeout_s * 1e3))))

    def publish_on(self, channel: str, data: bytes) -> None:
        """Publish ``data`` on another channel than the endpoint's own."""
        with self._guard:
            self.lcm.Publish(channel, data)

    def take_side(self, channel: str) -> list[bytes]:
        """The messages received on ``channel`` (one of ``also``) since the last call, oldest first."""
        out, self.side[channel] = self.side[channel], []
        return out

    def publish(self, data: bytes) -> float:
        """Publish ``data``; returns the wall time (``perf_counter``) it was handed to LCM (taken
        before the call: on a busy machine the receiver may run, and answer, before ``Publish``
        returns to this process)."""
        sent = time.perf_counter()
        with self._guard:
            self.lcm.Publish(self.publish_channel, data)
        return sent

    def _handle(self, timeout_ms: int = 0) -> int:
        with self._guard:
            return self.lcm.HandleSubscriptions(timeout_ms)

    def poll(self, timeout_s: float) -> list[tuple[float, bytes]]:
        """Messages received within ``timeout_s`` (0: only those waiting), oldest first.  On a
        ``memq://`` LCM (both sides in one process, ``in_memory``) the wait is a sleep between
        non-blocking handles: pydrake's ``HandleSubscriptions`` keeps Python's interpreter lock
        while it blocks, which would stop the other side's thread."""
        if self.url.startswith("memq"):
            deadline = time.perf_counter() + timeout_s
            while (
                self._handle() == 0
                and not self.inbox
                and not any(self.side.values())
                and time.perf_counter() < deadline
            ):  # (the other side's thread may have handled them)
                time.sleep(MEMQ_NAP)
        else:  # (whole ms, rounded down: a wait never ends past its deadline)
            self._handle(max(0, int(timeout_s * 1e3)))
        while self._handle() > 0:
            pass
        out, self.inbox = self.inbox, []
        return out


LCM_SHORT, LCM_FRAGMENT = 0x4C433032, 0x4C433033  # "LC02", "LC03": the magic of LCM's UDP packets


class SenderWatch:
    """Who publishes on some channels of a ``udpm://`` LCM group: a plain UDP socket joined to the
    group beside LCM's own (both bind the port with ``SO_REUSEADDR``: each gets every packet),
    reading each packet's source address and channel (LCM's packet header: magic, sequence
    number, then the NUL-terminated channel; a fragmented message names its channel in its first
    fragment).  Every process's LCM sends from a socket of its own, so two processes publishing
    on one channel show two source addresses — a sender identity LCM's messages do not carry.
    Unlike a ``DrakeLcm`` subscription, whose queue holds one message (pydrake's ``Subscribe``
    returns no handle to deepen it), the kernel's socket buffer keeps every packet until read."""

    def __init__(self, url: str, channels: tuple):
        parsed = urllib.parse.urlparse(url)
        group, port = parsed.hostname, parsed.port
        self.channels = {c.encode() for c in channels}
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if hasattr(socket, "SO_REUSEPORT"):
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEPORT, 1)
        self.sock.bind(("", port))
        membership = struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("0.0.0.0"))
        self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        self.sock.setblocking(False)

    @staticmethod
    def for_url(url: str, channels: tuple) -> Optional["SenderWatch"]:
        """A watch of ``url``'s group, or None where there is none (``memq://``) or the socket
        cannot join it."""
        if urllib.parse.urlparse(url).scheme != "udpm":
            return None
        try:
            return SenderWatch(url, channels)
        except OSError:
            return None

    def senders(self) -> list[tuple[str, tuple]]:
        """(channel, source address) of every packet on the watched channels received since the
        last call, oldest first."""
        out = []
        while True:
            try:
                data, source = self.sock.recvfrom(65536)
            except (BlockingIOError, InterruptedError):
                return out
            if len(data) < 8:
                continue
            magic = struct.unpack(">I", data[:4])[0]
            start = 8 if magic == LCM_SHORT else 20 if magic == LCM_FRAGMENT else None
            if start is None or (magic == LCM_FRAGMENT and struct.unpack(">H", data[16:18])[0] != 0):
                continue  # not LCM, or a later fragment (no channel name)
            end = data.find(b"\0", start)
            channel = data[start:end] if end > 0 else b""
            if channel in self.channels:
                out.append((channel.decode(), source))

    def close(self) -> None:
        self.sock.close()


def utime_of(t: float) -> int:
    """µs of a time in s (rounded: the period's multiples stay exact)."""
    return int(round(t * 1e6))


def pack_status(t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> bytes:
    """An ``lcmt_iiwa_status`` of the sample at ``t`` (s): q (rad), v (rad/s), τ (N·m)."""
    m = lcmt_iiwa_status()
    n = len(q)
    m.utime, m.num_joints = utime_of(t), n
    m.joint_position_measured = [float(x) for x in q]
    m.joint_velocity_estimated = [float(x) for x in v]
    m.joint_position_commanded = m.joint_position_ipo = [float(x) for x in q]
    m.joint_torque_measured = m.joint_torque_commanded = [float(x) for x in tau]
    m.joint_torque_external = [0.0] * n
    return m.encode()


def decoded_status(message_type, data: bytes, n: int, position: str, velocity: str) -> tuple:
    """(utime, q, v) of a status message of ``message_type`` whose fields ``position`` and
    ``velocity`` hold q and v; ValueError naming what is wrong (undecodable, another joint count)."""
    try:
        m = message_type.decode(data)
    except Exception as exc:  # noqa: BLE001  (the decoder raises ValueError or struct.error)
        raise ValueError(f"an undecodable status message ({type(exc).__name__})") from None
    q, v = getattr(m, position), getattr(m, velocity)
    if m.num_joints != n or len(q) != n or len(v) != n:
        raise ValueError(f"a status of {m.num_joints} joints, the scenario's arm has {n}")
    return m.utime, np.array(q), np.array(v)


def unpack_status(data: bytes, n: int) -> tuple[int, np.ndarray, np.ndarray]:
    """(utime, q, v) of an ``lcmt_iiwa_status``; ValueError naming what is wrong."""
    return decoded_status(lcmt_iiwa_status, data, n, "joint_position_measured", "joint_velocity_estimated")


def status_torque(data: bytes) -> np.ndarray:
    """``joint_torque_commanded`` of a (checked) status: the torque the hardware applied over its
    last step (N·m)."""
    return np.array(lcmt_iiwa_status.decode(data).joint_torque_commanded, dtype=float)


def pack_command(utime: int, tau: np.ndarray, positions: Optional[np.ndarray] = None) -> bytes:
    """An ``lcmt_iiwa_command`` answering the status of ``utime``: τ (N·m), and ``positions``
    (rad; ``num_joints`` = their count, 0 without: ``driver_modes`` says which positions)."""
    m = lcmt_iiwa_command()
    m.utime = int(utime)
    m.joint_position = [] if positions is None else [float(x) for x in positions]
    m.num_joints = len(m.joint_position)
    m.num_torques, m.joint_torque = len(tau), [float(x) for x in tau]
    return m.encode()


def unpack_command(data: bytes, n: int) -> tuple[int, np.ndarray]:
    """(utime, τ) of a command for ``n`` joints; ValueError naming what is wrong
    (``unpack_command_positions``)."""
    utime, tau, _ = unpack_command_positions(data, n)
    return utime, tau


def unpack_command_positions(data: bytes, n: int) -> tuple[int, np.ndarray, Optional[np.ndarray]]:
    """(utime, τ, positions or None) of a command for ``n`` joints; ValueError naming what is
    wrong (undecodable, a wrong number of torques or positions)."""
    try:
        m = lcmt_iiwa_command.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable command message ({type(exc).__name__})") from None
    if m.num_torques != n or len(m.joint_torque) != n:
        raise ValueError(f"a command of {m.num_torques} torques, the arm has {n} joints")
    if m.num_joints not in (0, n):
        raise ValueError(f"a command of {m.num_joints} positions (0 or {n})")
    positions = np.array(m.joint_position, dtype=float) if m.num_joints else None
    return m.utime, np.array(m.joint_torque, dtype=float), positions


def pack_wsg_status(t: float, fingers: np.ndarray, drive_force: np.ndarray) -> bytes:
    """An ``lcmt_schunk_wsg_status`` of the sample at ``t``: ``fingers`` = [q_left, q_right, v_left,
    v_right] (m, m/s), ``drive_force`` = each finger drive's force (N, − squeezes)."""
    m = lcmt_schunk_wsg_status()
    m.utime = utime_of(t)
    m.actual_position_mm = 1e3 * (float(fingers[0]) + float(fingers[1]))
    m.actual_speed_mm_per_s = 1e3 * max(abs(float(fingers[2])), abs(float(fingers[3])))
    m.actual_force = min(-float(drive_force[0]), -float(drive_force[1]))
    return m.encode()


def unpack_wsg_status(data: bytes) -> tuple[int, np.ndarray, np.ndarray]:
    """(utime, fingers, drive force) of an ``lcmt_schunk_wsg_status`` in ``GraspObserver``'s input
    layout: the opening split evenly between the fingers, each at the reported speed and each drive
    squeezing with the reported force (what the observer's rule reads of them is exactly the
    message's width, speed and force)."""
    try:
        m = lcmt_schunk_wsg_status.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable gripper status ({type(exc).__name__})") from None
    half, speed = 0.5 * (m.actual_position_mm / 1e3), m.actual_speed_mm_per_s / 1e3
    return m.utime, np.array([half, half, speed, speed]), np.array([-m.actual_force, -m.actual_force])


def pack_wsg_command(utime: int, opening: float, force: float) -> bytes:
    """An ``lcmt_schunk_wsg_command`` for the gripper driver's tick ``utime``: the wanted opening (m;
    ≤ 0: close) and the force limit (N)."""
    m = lcmt_schunk_wsg_command()
    m.utime, m.target_position_mm, m.force = int(utime), 1e3 * max(float(opening), 0.0), float(force)
    return m.encode()


def unpack_wsg_command(data: bytes) -> tuple[int, float, float]:
    """(utime, opening in m, force in N) of an ``lcmt_schunk_wsg_command``; ValueError when undecodable."""
    try:
        m = lcmt_schunk_wsg_command.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable gripper command ({type(exc).__name__})") from None
    return m.utime, m.target_position_mm / 1e3, m.force


def pack_tracked(t: float, report: np.ndarray) -> bytes:
    """An ``lcmt_scope`` of a pose tracker's report at ``t`` (``TRACKED_SIZE`` doubles a body)."""
    m = lcmt_scope()
    m.utime, m.size, m.value = utime_of(t), len(report), [float(x) for x in report]
    return m.encode()


def unpack_tracked(data: bytes, bodies: int) -> tuple[int, np.ndarray]:
    """(utime, report) of a tracker's message for ``bodies`` bodies; ValueError naming what is wrong."""
    try:
        m = lcmt_scope.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable tracker message ({type(exc).__name__})") from None
    if m.size != TRACKED_SIZE * bodies:
        raise ValueError(
            f"a tracker message of {m.size} values, the scenario's {bodies} tracked bodies need "
            f"{TRACKED_SIZE * bodies}"
        )
    return m.utime, np.array(m.value, dtype=float)


def spread(values, scale: float = 1.0) -> Optional[dict]:
    """Median, p99 and max of ``values`` × ``scale`` (None when empty)."""
    a = np.asarray(values, dtype=float) * scale
    if a.size == 0:
        return None
    return {
        "median": float(np.median(a)),
        "p99": float(np.percentile(a, 99)),
        "max": float(a.max()),
        "count": int(a.size),
    }
