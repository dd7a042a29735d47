"""The hardware side's session on the LCM link: the status it publishes, the commands it takes
and checks, the timing it records; ``command_link.CommandLink`` calls it at each tick.

- **Lockstep** (``lockstep``): each tick waits for its command (re-sending the status every
  ``resend`` s of wall time, so a lost status costs time, not the run), up to ``command_timeout``
  of wall time.
- **Real time**: the link paces the ticks and skips those of its own stalls (``realtime.TickPacer``);
  each tick waits at most ``budget`` × T for its command, otherwise the newest command that
  came stays (``late``); ``silent_periods`` statuses in a row without any command of the
  controller (5: a dead or silent controller; ``realtime.Silence``) is the timeout, so the arm
  is held that many control periods after the tick the controller was last heard in.

Every command passes the checks before it reaches the plant (``HardwareSession._check``): its
size, finite torques within the actuators' effort limits, positions (if any) equal to the status's
measured ones (a torque-only driver: ``driver_modes.position_refusal``), and one command per status — LCM
carries no sender identity, so a second sender shows up as a command for a status nobody asked
about, two different commands for one status, or a time stamp that goes backwards.  A failed
check or a timeout is a *fault*: the link stops publishing status, and the arm is held for
``hold_time`` s (a position hold at the joint angles of the fault with gravity compensation,
computed from the arm's model — the driver side may use its model; damping alone does not hold
the RV-M1), then the run ends with ``LinkFault`` naming it.
"""

from __future__ import annotations

import signal
import time
from contextvars import ContextVar
from typing import Optional

import numpy as np

from ptint_drake.hardware.camera_link import image_channel, pack_depth_image
from ptint_drake.hardware.driver_modes import position_refusal
from ptint_drake.hardware.gripper_commands import GripperCommands
from ptint_drake.hardware.link_record import LinkRecord, LinkSettings
from ptint_drake.hardware.process import quiet_collector, request_realtime
from ptint_drake.hardware.realtime import Silence, TickPacer
from ptint_drake.worlds.base import LinkPorts
from ptint_drake.hardware.arm_messages import arm_messages
from ptint_drake.hardware.link import (TRACKER_CHANNEL, WSG_COMMAND_CHANNEL, WSG_STATUS_CHANNEL, Endpoint,
                                       pack_tracked, pack_wsg_status, utime_of)

SETTLED_SPEED = 0.05  # rad/s: the arm counts as held below this joint speed
QUIET, QUIET_MAX = 0.1, 2.0  # s: the wait for the last answers to the hand-shake (``_quiet``)
WAIT_NAP = 1e-4  # s: a nap of a wait's last millisecond (``Endpoint.poll`` waits whole ms)


class LinkFault(Exception):
    """A fault of the link (the message is the one-line reason)."""


ACTIVE: ContextVar[Optional["HardwareSession"]] = ContextVar("ptint_hardware_session", default=None)


class HardwareSession:
    """The hardware side of the link: publishes status, takes and checks commands, records the
    timing (``record``).  ``limits``: the actuators' effort limits (N·m, actuator order)."""

    def __init__(self, endpoint: Endpoint, n: int, limits: np.ndarray, settings: LinkSettings):
        self.endpoint, self.n, self.limits, self.s = endpoint, n, np.asarray(limits, float), settings
        self.messages = arm_messages(settings.messages)  # the arm's status and command types
        self.record = LinkRecord()
        self._rng = np.random.default_rng(settings.seed)
        self._answered: Optional[int] = None  # utime of the last status answered
        self._answered_tau: Optional[np.ndarray] = None
        self._pending: Optional[int] = None
        self._measured: dict[int, np.ndarray] = {}  # utime → the measured positions of a status sent
        self._late_taken = False  # real time: a late answer's torque taken during this tick's wait
        self._answer_wall = float("nan")  # perf_counter of this tick's answer handled (``_waited``)
        self._sent: dict[int, float] = {}  # utime → wall time of its first publish
        self._consecutive_late = 0
        self.pacer = TickPacer(settings.period, settings.realtime_rate)  # real time (``realtime``)
        self.silence = Silence(settings.silent_periods)
        self._after_handshake = False
        self.ports: Optional[LinkPorts] = None  # the station's gripper and objects (``sim_hardware``)
        self._wsg = GripperCommands()  # gripper commands by the driver's tick (a station's gripper)
        self._companions: list = []  # this tick's gripper status, tracker report, frame (``ports``)
        self._drop_gripper = False  # ``drop_companion``: this tick's gripper status not sent once
        self.handshake_s: Optional[float] = None  # wall s the hand-shake took
        self.builds = 0  # CommandLinks built in this session (more than one: a world planned anew)
        self.watch = (
            None  # a ``link.SenderWatch`` of the command channels (udpm URLs), set by ``sim_hardware``
        )
        self._controller: Optional[tuple] = None  # the source address of the first command (the controller)
        self.warn = None  # a callable for warnings during the run (``sim_hardware``)
        self._stop: Optional[int] = None  # a signal received (``stop_on_signals``), not yet acted on

    # -- stopping -------------------------------------------------------------------------------
    def request_stop(self, signum: int) -> None:
        """A stop asked for (SIGINT or SIGTERM): the next tick, or the wait for a command, is the
        fault ``stopped``, and the arm is held as after any other fault."""
        self._stop = signum

    def _check_stop(self, t: float) -> None:
        if self._stop is not None and self.record.fault is None:
            self.record.stop_signal = self._stop
            self._fail(t, "stopped", f"stopped by {signal.Signals(self._stop).name} at t = {t:.3f} s")

    # -- the protocol -------------------------------------------------------------------------
    def _publish(self, data: bytes) -> float:
        for channel, message in self._companions:  # before the arm's status: it completes a tick
            if self._drop_gripper and channel == WSG_STATUS_CHANNEL:
                self._drop_gripper, self.record.companions_dropped = False, self.record.companions_dropped + 1
                continue
            self.endpoint.publish_on(channel, message)
        if self.s.drop_status > 0 and self._rng.random() < self.s.drop_status:
            self.record.dropped += 1
            return time.perf_counter()
        self.record.statuses += 1
        return self.endpoint.publish(data)

    def _fail(self, t: float, kind: str, message: str) -> None:
        if self.record.fault is None:
            self.record.fault, self.record.fault_time, self.record.fault_kind = message, t, kind

    def _matched(self, utime: int, positions: Optional[np.ndarray]) -> tuple[int, Optional[str]]:
        """(the stamp of the status a command answers, why its positions are refused or None).
        Drake's ``IiwaCommandSender`` truncates t·10⁶: a stamp 1 µs short of the pending or
        answered status's is that status's answer (48 of 3001 stamps at 1 ms, measured)."""
        if utime not in self._sent and utime + 1 in self._sent:
            utime += 1
        return utime, position_refusal(positions, self._measured.get(utime))

    def _check(self, t: float, data: bytes, t_recv: float) -> None:
        """One received command against the checks (module docstring); a fault or its use."""
        try:
            utime, tau, positions = self.messages.unpack_command_positions(data, self.n)
        except ValueError as exc:
            return self._fail(t, "bad command", f"command rejected at t = {t:.3f} s: {exc}")
        utime, refusal = self._matched(utime, positions)
        if refusal:  # a torque-only driver: positions that mean something are refused, not ignored
            return self._fail(t, "bad command", f"command rejected at t = {t:.3f} s: {refusal}")
        if not np.all(np.isfinite(tau)):
            return self._fail(
                t,
                "bad command",
                f"command rejected at t = {t:.3f} s: a non-finite torque {np.array2string(tau, precision=3)}",
            )
        over = np.abs(tau) > self.limits * (1 + 1e-9)
        if np.any(over):
            j = int(np.argmax(over))
            return self._fail(
                t,
                "bad command",
                f"command rejected at t = {t:.3f} s: joint {j} torque "
                f"{tau[j]:.3g} N·m beyond its limit {self.limits[j]:.3g} N·m",
            )
        if utime == self._answered:
            if np.array_equal(tau, self._answered_tau):
                self.record.duplicates += 1
                return None
            return self._fail(
                t,
                "second sender",
                f"two different commands for the status of t = "
                f"{utime * 1e-6:.3f} s at t = {t:.3f} s: a second sender "
                f"on {self.endpoint.listen}",
            )
        if utime == self._pending:
            self._answered, self._answered_tau = utime, tau
            self.record.accepted += 1
            self.record.last_command_t = utime * 1e-6
            self.record.rtt.append(t_recv - self._sent[utime])
            self._answer_wall, self.record.last_heard_t = t_recv, t
            return None
        if self._answered is not None and utime < self._answered:
            return self._fail(
                t,
                "second sender",
                f"command time stamps went backwards at t = {t:.3f} s "
                f"({utime * 1e-6:.3f} s after {self._answered * 1e-6:.3f} s):"
                f" a second sender on {self.endpoint.listen} or a "
                f"restarted controller",
            )
        if utime in self._sent and (self._pending is None or utime < self._pending):
            return self._late(t, utime, tau, t_recv)
        return self._fail(
            t,
            "second sender",
            f"a command for t = {utime * 1e-6:.6g} s that no status asked "
            f"for, at t = {t:.3f} s: a second sender on {self.endpoint.listen}",
        )

    def _late(self, t: float, utime: int, tau: np.ndarray, t_recv: float) -> None:
        """Real time: an answer to an older status than the pending one, after its tick, but newer
        than the command in use: the controller's newest word, taken at this tick (a robot's
        driver applies the latest command it has; the torque of an older status would stay
        otherwise, and a controller one status behind would never steer the arm).  An answer to
        one of the last ``silent_periods`` statuses is also a sign of life (``realtime``)."""
        self.record.late_commands += 1
        self._answered, self._answered_tau, self._late_taken = utime, tau, True
        self.record.last_command_t = utime * 1e-6
        if self._pending - utime <= self.s.silent_periods * utime_of(self.s.period):
            self.silence.heard()
            self.record.last_heard_t = t
        self.record.late_utime.append(utime)
        self.record.late_wall.append(t_recv)

    def _check_gripper(self, t: float, data: bytes) -> None:
        """One received gripper command against the checks (``GripperCommands.check``)."""
        fault = self._wsg.check(t, data, self.ports.gripper_max_force)
        if fault is not None:
            self._fail(t, *fault)

    def gripper_opening(self, utime: int) -> Optional[float]:
        """The gripper command (the wanted opening, m) for the driver's tick ``utime``, if received."""
        return self._wsg.opening(utime)

    def _check_senders(self, t: float) -> None:
        """Every packet on the command channels must come from the controller's address (the first
        command's): another is a second sender (``link.SenderWatch``)."""
        if self.watch is None:
            return
        for channel, source in self.watch.senders():
            if self._controller is None:
                self._controller = source
            elif source != self._controller:
                self._fail(
                    t,
                    "second sender",
                    f"a command on {channel} from a second sender at t = {t:.3f} s "
                    f"(from {source[0]}:{source[1]}; the controller sends from "
                    f"{self._controller[0]}:{self._controller[1]})",
                )
                return

    def _complete(self, utime: int, wsg: Optional[int]) -> bool:
        """Whether the answer to the status of ``utime`` is in: the arm's command, and with a
        gripper the gripper command for the driver's tick ``wsg``."""
        return self._answered == utime and (wsg is None or wsg in self._wsg)

    def _wait(
        self, t: float, utime: int, wait: float, data: bytes, resend: bool, wsg: Optional[int] = None
    ) -> bool:
        """Wait up to ``wait`` s (wall) for the command of ``utime`` (and the gripper command for
        the driver's tick ``wsg``, when given); True when it came."""
        deadline = time.perf_counter() + wait
        last_sent = time.perf_counter()
        while True:
            now = time.perf_counter()
            step = min(deadline - now, self.s.resend) if resend else deadline - now
            messages = self.endpoint.poll(max(step, 0.0))
            self._check_senders(t)  # first: a second sender is named by its address, not its stamps
            for t_recv, message in messages:
                self._check(t, message, t_recv)
            self._check_stop(t)
            if self.ports is not None:
                for message in self.endpoint.take_side(WSG_COMMAND_CHANNEL):
                    self._check_gripper(t, message)
            if self.record.fault is not None:
                return False
            if self._complete(utime, wsg):
                return True
            now = time.perf_counter()
            if now >= deadline:
                return False
            if resend and now - last_sent >= self.s.resend:
                self.record.resends += 1
                last_sent = self._publish(data)
            elif deadline - now < 1e-3:  # below LCM's millisecond waits: short naps to the deadline
                time.sleep(min(deadline - now, WAIT_NAP))

    def _set_companions(self, t: float, extras) -> None:
        """The station's messages of the tick at ``t`` beside the arm's (``extras`` = fingers,
        drive forces, the tracker's report, the depth frame; None: the arm alone)."""
        if extras is None or self.ports is None:
            self._companions = []
            return
        fingers, force, tracked, image = extras
        self._companions = [(WSG_STATUS_CHANNEL, pack_wsg_status(t, fingers, force))]
        drop = self.s.drop_companion  # (a test: the gripper status's first publish is lost)
        self._drop_gripper = (drop is not None and utime_of(t) == utime_of(drop)
                              and not self.record.companions_dropped)
        if tracked is not None:
            self._companions.append((TRACKER_CHANNEL, pack_tracked(t, tracked)))
        if image is not None:  # the camera's frame of this tick's period: before the status too
            camera = self.ports.camera
            self._companions.append((image_channel(camera), pack_depth_image(t, image, camera)))
            self.record.frames_sent += 1

    def handshake(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, extras=None) -> None:
        """Before the simulation starts: the status of the start pose at t = 0 until its command
        comes (a ``LinkFault`` after ``startup_timeout``), so that the controller may start
        second and starts from the arm's pose; the first tick then sends the status of t = 0
        after the plant's first step (a second sample of t = 0, answered anew)."""
        quiet_collector()
        if not self.s.lockstep:  # after the diagram's build: the loop alone runs at that priority
            refused = request_realtime(self.s.priority, self.endpoint.threads)
            if refused and self.warn is not None:
                self.warn(refused)
        start = time.perf_counter()
        data = self.messages.pack_status(0.0, q, v, tau)
        self._set_companions(0.0, extras)
        self._pending, self._measured[0] = 0, np.array(q, dtype=float)
        self._sent[0] = self._publish(data)
        wsg = 0 if self.ports is not None else None  # the gripper command the driver takes at t = 0
        if not self._wait(0.0, 0, self.s.startup_timeout, data, resend=True, wsg=wsg):
            if self.record.fault is not None:
                raise LinkFault(self.record.fault)
            raise LinkFault(
                f"no command within the start-up timeout of {self.s.startup_timeout:g} s on "
                f"{self.endpoint.url} (channel {self.endpoint.listen}): is `ptint drive` running?"
            )
        self.handshake_s = time.perf_counter() - start
        self._quiet()
        self.record.rtt.clear()  # the start-up wait is no round trip
        self.record.accepted = 0
        # the tick at t = 0 samples the arm after the plant's first step: a new status of t = 0
        self._answered, self._answered_tau, self._after_handshake = None, None, True

    def _quiet(self) -> None:
        """After the hand-shake: take the drive's answers to the hand-shake's re-sent statuses
        (stamped t = 0 like the first tick's) until none came for ``QUIET`` s (at most
        ``QUIET_MAX``), so that none of them is taken for the first tick's answer."""
        start = last = time.perf_counter()
        while True:
            got = self.endpoint.poll(0.01)
            self._check_senders(0.0)
            if self.ports is not None:
                for message in self.endpoint.take_side(WSG_COMMAND_CHANNEL):
                    self._check_gripper(0.0, message)
            now = time.perf_counter()
            if got:
                self.record.duplicates += len(got)
                last = now
            if now - last >= QUIET or now - start >= QUIET_MAX:
                return

    def _waited(self) -> None:
        """The tick's wait ended: when, and when its answer came (NaN: it did not)."""
        self.record.tick_answered.append(self._answer_wall)
        self.record.tick_waited.append(time.perf_counter())

    def exchange(
        self, t: float, q: np.ndarray, v: np.ndarray, tau: np.ndarray, extras=None
    ) -> Optional[np.ndarray]:
        """The tick at ``t``: publish the status (and with a gripper, first, the gripper's status
        and the tracker's report: ``extras``), take its command (None: none, keep the last torque;
        ``record.fault`` says when that is a fault); the gripper command for the driver's next
        tick is then ``gripper_opening(utime_of(t) + utime_of(T))`` when it came."""
        utime = utime_of(t)
        wsg = utime + utime_of(self.s.period) if self.ports is not None else None
        self._check_stop(t)
        if self.record.fault is not None:
            return None
        if not self.s.lockstep and not self.pacer.admit(t):
            return None  # the hardware's own stall: this tick skipped, no status (``realtime``)
        self.record.tick_time.append(t)
        self.record.tick_wall.append(time.perf_counter())
        if self._after_handshake:  # answers to re-sent hand-shake statuses, before this status existed
            self._after_handshake = False
            self.record.duplicates += len(self.endpoint.poll(0.0))
        data = self.messages.pack_status(t, q, v, tau)
        self._set_companions(t, extras)
        self._pending, self._measured[utime] = utime, np.array(q, dtype=float)
        self._sent[utime] = self._publish(data)
        self._answer_wall = float("nan")
        self.record.tick_sent.append(self._sent[utime])
        if len(self._sent) > 4096:
            for key in sorted(self._sent)[:2048]:
                del self._sent[key]
                self._measured.pop(key, None)
        if self.s.lockstep:
            came = self._wait(t, utime, self.s.command_timeout, data, resend=True, wsg=wsg)
            self._waited()
            if came:
                return self._answered_tau
            self._fail(
                t,
                "command timeout",
                f"command timeout at t = {t:.3f} s (no command for {self.s.command_timeout * 1e3:.0f} ms)",
            )
            return None
        return self._realtime_wait(t, utime, data)

    def _realtime_wait(self, t: float, utime: int, data: bytes) -> Optional[np.ndarray]:
        """Real time: the tick's wait for its command (``budget`` × T of wall time), then the
        silence rule (``realtime.Silence``: ``silent_periods`` statuses in a row without any
        command of the controller is the fault ``command timeout``)."""
        self.silence.start_tick()
        self._late_taken = False
        came = self._wait(t, utime, self.s.budget * self.s.period / self.s.realtime_rate, data, resend=False)
        self._waited()
        if self.record.fault is not None:
            return None
        self._consecutive_late = 0 if came else self._consecutive_late + 1
        if not came:
            self.record.late += 1
            self.record.late_run_max = max(self.record.late_run_max, self._consecutive_late)
        if self.silence.end_tick(came):
            self._fail(
                t,
                "command timeout",
                f"command timeout at t = {t:.3f} s (no command for {self.silence.count} statuses in a "
                f"row: the controller is silent or gone)",
            )
            return None
        return self._answered_tau if came or self._late_taken else None
