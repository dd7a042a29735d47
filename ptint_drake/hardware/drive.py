"""``ptint drive``: the controller side alone — the scenario's targets and controller, answering each
status of the arm with a torque command over LCM.

``DriveDiagram`` is the scenario's controller in its slot (``controllers.AddControllerTo``, the
same code path as ``ptint run``) between an exported input ``state`` (the arm's [q; v] from the
last status) and an exported output ``actuation``, with the analytic targets (``TargetView``), no
plant: the controller's kinematics come from the arm's model as written (``robot.nominal_plant``).
The drive adds no hold: the hardware side samples and holds (``command_link``).

``run_drive`` answers each status stamped t_k: the controller's own state (σ) is advanced to t_k
with the previous status's [q; v] (``Simulator.AdvanceTo``, then ``EVENT_STEP`` further for the
controller's events at t_k), as the one-process run's controller sees a discrete plant's state
between two steps; then the state input is set to this status's [q; v] (initialized at the first
status, so that the controller's start is the arm's), and the command stamped with the status's
``utime`` carries its output. A status repeated (the hardware re-sends an unanswered one) gets the
same command again; a second status of the same time with another state (the first tick after the
hand-shake: the arm after the plant's first step) a new one. Torques beyond the actuators' effort
limits are clipped to them (``limits.saturate``, the default: where ``ptint run``'s station
saturates; the hardware side rejects them as a fault). It ends when it has answered the last tick
(t ≥ duration − 1.5 T), or with ``DriveFault`` (one line): no status within the start-up timeout,
no status for ``status_timeout`` s, or a status of the wrong size. The drive never stops the arm by
a message (no NaN, nothing the hardware must reject): it stops commanding, and the hardware holds
the arm after ``LinkSettings.silent_periods`` periods without a command. A second sender is the
hardware's to find, by the packets' source addresses (``link.SenderWatch``); the drive does not
compare the status's torque echo with its own commands (a driver may add its own terms, e.g.
gravity compensation, to what it reports). A controller side with a camera fits its frames in a
process of its own (``side.frames``: ``systems.perception.frame_process``): the loop hands each
frame's message over as received and writes the fits in when their samples are due.
"""

from __future__ import annotations

import copy
import time
from typing import Callable, Optional

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig

from ptint_drake.config.schema import Scenario
from ptint_drake.hardware.arm_messages import arm_messages
from ptint_drake.hardware.link import WSG_COMMAND_CHANNEL, Endpoint, pack_wsg_command, url_warning
from ptint_drake.systems.perception.frame_process import FrameError
from ptint_drake.hardware.camera_link import with_receive_buffer
from ptint_drake.hardware.companions import CompanionFault, CompanionInbox, companion_channels
from ptint_drake.hardware.drive_diagram import DriveDiagram
from ptint_drake.hardware.drive_record import DriveRecord, DriveSettings, drive_series, drive_summary
from ptint_drake.hardware.driver_modes import DriverTerms
from ptint_drake.hardware.status_clock import StatusClock
from ptint_drake.hardware.process import quiet_collector, request_realtime
from ptint_drake.robot.plant import actuator_effort_limits, nominal_plant
from ptint_drake.systems.hand.gripper import GRASP_STATES
from ptint_drake.worlds.base import TRACKER_PORT, new_simulator
from ptint_drake.worlds.registry import world_of

# s: after integrating σ to a status's time t, a step this short takes the controller's events at t
# (a segment's start stores s(t0)) with that status's state, as the one-process run's do
EVENT_STEP = 1e-9
# statuses lost within this many periods of the run's end: the run ended (a timeout then is not a fault)
END_SLACK = 20
WARM_UP_PERIODS = 3  # control periods of the throwaway run after the hand-shake (``warm_up``)
FRAME_DECODER = "ptint_drake.hardware.camera_link:unpack_depth_image"  # a frame's, in its process


class DriveFault(Exception):
    """The drive stopped commanding (the message is the one-line reason)."""


class _DriveLoop:
    """``run_drive``'s loop state: the controller's simulator, the LCM endpoint, the last status
    answered and the commands sent lately; a method per step (wait for statuses, check one,
    answer it)."""

    def __init__(
        self,
        scenario: Scenario,
        settings: DriveSettings,
        record: DriveRecord,
        url: Optional[str],
        warn: Callable[[str], None],
        lcm=None,
    ) -> None:
        diagram, _, n, side = DriveDiagram(scenario)
        self.warn, self.in_memory = warn, lcm is not None  # (memq: both sides in one process)
        self.n, self.settings, self.record, self.side = n, settings, record, side
        self.period_us = int(round(settings.period * 1e6))
        # the driver's stamps to scenario time, and what the driver adds to a command
        self.clock = record.clock = StatusClock(settings.period)
        self.messages = arm_messages(settings.messages)  # the arm's status and command types
        self.terms = DriverTerms(settings.driver_mode, nominal_plant(scenario), self.messages)
        # the drive's own saturation, where ``ptint run``'s station saturates (``limits.saturate``):
        # the hardware side rejects a torque beyond an effort limit as a fault
        self.limits = actuator_effort_limits(nominal_plant(scenario)) if scenario.limits.saturate else None
        self.simulator = new_simulator(diagram)
        config = copy.copy(scenario.simulator)
        own = world_of(scenario).simulator_config(scenario)
        if own is not None:  # the world's own integrator settings, as in ``ptint run``
            config = copy.copy(own)
        config.target_realtime_rate = 0.0  # the hardware's status paces the drive
        ApplySimulatorConfig(config, self.simulator)
        self.config = config
        self.context = self.simulator.get_mutable_context()
        self.state_in, self.out = diagram.GetInputPort("state"), diagram.GetOutputPort("actuation")
        self.ports = ports = world_of(scenario).link_ports(scenario) if side is not None else None
        also = companion_channels(ports)
        if ports is not None and ports.camera and lcm is None:  # a depth frame is hundreds of kB
            url = with_receive_buffer(url)
        status, command = self.messages.status_channel, self.messages.command_channel
        self.endpoint = Endpoint(url, listen=status, publish=command, also=also, lcm=lcm)
        record.channels = [status, *also]
        self.frames = getattr(side, "frames", None)  # a perception in a process of its own
        if side is not None:
            self.gripper_in = diagram.GetInputPort("gripper")
            self.tracked_in = diagram.GetInputPort(TRACKER_PORT) if ports.objects else None
            self.depth_in = diagram.GetInputPort("depth_image") if ports.camera else None
            self.grasp_out = diagram.GetOutputPort("grasp_state")
            self.inbox = CompanionInbox(self.endpoint, ports, settings.period, settings.status_timeout,
                                        raw_frames=self.frames is not None)
        if self.frames is not None:
            self.frames.start(decoder=FRAME_DECODER)
        record.url, record.threads = self.endpoint.url, self.endpoint.threads
        risk = url_warning(self.endpoint.url)
        if risk:
            warn(risk)
        self.answered: Optional[int] = None  # scenario µs of the last status answered
        self.stamp: Optional[int] = None  # the driver's stamp of the status answered last
        self.answer = b""
        self.last_q = self.last_v = None
        self.started = False  # with a controller side: the events at the first tick's time taken
        self.end = settings.duration - 1.5 * settings.period
        self.quiet_end = False
        self.last_seen = time.perf_counter()

    def wait(self) -> list:
        """The next statuses received (polling until some arrive); ``DriveFault`` after the
        start-up or status timeout without one."""
        while True:
            # until the first tick after the hand-shake (two commands: the hand-shake's and that
            # tick's; a drive started mid-run: its first two), the hardware may still be building
            s = self.settings
            timeout = s.startup_timeout if self.record.commands < 2 else s.status_timeout
            messages = self.endpoint.poll(0.05)
            now = time.perf_counter()
            if messages:
                self.last_seen = now
                return messages
            if now - self.last_seen >= timeout:
                if self.answered is None:
                    raise DriveFault(
                        f"no status from the hardware within the start-up timeout of {timeout:g} s on "
                        f"{self.endpoint.url} (channel {self.messages.status_channel}): is `ptint hardware` "
                        f"running?"
                    )
                last = self.answered * 1e-6
                if last >= self.end - END_SLACK * self.settings.period:
                    # the run's last statuses were lost (LCM drops under load): the hardware has
                    # ended, this is the run's end, not a fault; the missing ticks count as gaps
                    self.record.gaps += max(0, int(round((self.end - last) / self.settings.period)))
                    self.quiet_end = True
                    return []
                raise DriveFault(
                    f"no status from the hardware for {timeout:g} s after t = {self.answered * 1e-6:.3f} s: "
                    f"stopped commanding"
                )

    def take(self, t_recv: float, data: bytes) -> None:
        """One status received at wall time ``t_recv``: re-send the answer to a repeat, skip a stale
        one, otherwise check it and answer it."""
        try:
            stamp, q, v = self.messages.unpack_status(data, self.n)
        except ValueError as exc:
            raise DriveFault(f"status rejected: {exc}; stopped commanding") from None
        self.record.statuses += 1
        answered = self.answered
        utime = self.clock.place(stamp)  # scenario µs (``status_clock``); the command keeps the stamp
        if utime is None:
            self.record.stale += 1
            return
        if (
            answered is not None
            and utime == answered
            and stamp == self.stamp
            and np.array_equal(q, self.last_q)
            and np.array_equal(v, self.last_v)
        ):
            self.record.repeats += 1
            if self.side is not None:
                self.endpoint.publish_on(WSG_COMMAND_CHANNEL, self.gripper_answer)
            self.endpoint.publish(self.answer)
            return
        if answered is not None:
            self.record.gaps += max(0, int(round((utime - answered) * 1e-6 / self.settings.period)) - 1)
        companion = self.companion(stamp) if self.side is not None else None
        if self.side is not None and companion is None:  # one of its companions lost: skipped
            self.record.companions_lost = self.inbox.lost
            return
        self.stamp = stamp
        self.respond(t_recv, utime, q, v, companion)

    def companion(self, utime: int) -> Optional[dict]:
        """The companions of the status of ``utime`` (``CompanionInbox``; None: one was lost)."""
        try:
            return self.inbox.take(utime, handshake=self.answered is None)
        except CompanionFault as exc:
            raise DriveFault(str(exc)) from None

    def check_grasp(self, utime: int) -> None:
        """At a grasp read of the plan (its checks, and from a close command on every
        ``SENSE_PERIOD``): ``DriveFault`` when the world's rule would plan anew there (the controller
        side's ``stands``) — a retry or abort is not supported across processes."""
        if utime not in self.side.reads:  # (no read here: the observer is not evaluated)
            return
        state = int(self.grasp_out.Eval(self.context)[0])
        if self.side.stands(utime, state):  # the world's own rule (``World.controller_side``)
            return
        raise DriveFault(
            f"the grasp check at t = {utime / 1e6:.3f} s read {GRASP_STATES[state]!r}: a retry "
            f"(a new plan) is not supported across processes; stopped commanding"
        )

    def torque(self, t: float, q: np.ndarray, v: np.ndarray, companion: Optional[dict] = None) -> np.ndarray:
        """The controller's torque at the status's time ``t`` for its [q; v] (module docstring),
        clipped to the effort limits when saturating.  With a controller side ``companion`` holds the
        tick's gripper status and tracker report: the report is read like the arm's state; the
        gripper status is the grasp observer's at its update at ``t`` (a periodic update like
        the one-process run's hold, which samples the arm after the plant's step)."""
        if self.answered is None:  # the controller's start (s(t0) of the first segment) is the arm's
            self._fix(q, v, companion)
            self._frame(t, companion, handshake=True)
            self.context.SetTime(t)
            self.simulator.Initialize()
        elif companion is not None and (t > self.context.get_time() or not self.started):
            # a controller side: σ over (t_prev, t] with the previous sample; the grasp check reads
            # the observer there (as the world's run does at its stop); then the events at t with
            # that sample, the observer's update with this tick's gripper status, by a second
            # ``AdvanceTo(t)`` (at the time reached it takes the events due, as ``ptint run``'s
            # runner does at its stops: ``WorldRun.advance_at_reached_stops``; the first tick, at
            # t = 0 as the hand-shake, takes the events at t = 0 so); only then the new sample
            self.started = True
            if self.frames is not None:  # the frames whose samples are visible by t, written
                self.frames.take_due(self.context, t)
            self.simulator.AdvanceTo(t)
            self.check_grasp(int(round(t * 1e6)))
            self.gripper_in.FixValue(self.context, companion["gripper"])
            self._frame(t, companion)  # this period's frame, before the perception's event in it
            self.simulator.AdvanceTo(t)
        elif t > self.context.get_time():
            # σ over (t_prev, t] sees the previous sample, as the one-process run's controller
            # sees the discrete plant's state between two steps; then the events at t (segment
            # starts) with it too, and only then the new sample
            self.simulator.AdvanceTo(t)
            self.simulator.AdvanceTo(t + EVENT_STEP)
        self._fix(q, v, companion)
        tau = np.array(self.out.Eval(self.context), dtype=float)
        if self.limits is not None and np.any(np.abs(tau) > self.limits):
            self.record.clipped += 1
            tau = np.clip(tau, -self.limits, self.limits)
        return tau

    def _fix(self, q: np.ndarray, v: np.ndarray, companion: Optional[dict]) -> None:
        """The diagram's inputs: a status's [q; v] and, with a controller side, its companions."""
        self.state_in.FixValue(self.context, np.concatenate([q, v]))
        if companion is not None:
            if "tracked" in companion:
                self.tracked_in.FixValue(self.context, companion["tracked"])
            self.gripper_in.FixValue(self.context, companion["gripper"])

    def _frame(self, t: float, companion: Optional[dict], handshake: bool = False) -> None:
        """A depth frame that came with the status of ``t``: to the perception's process, or input."""
        if companion is not None and "image" in companion and self.frames is not None:
            self.frames.submit(t, companion["image"], handshake)  # (as received: its bytes)
        elif companion is not None and "image" in companion:
            self.depth_in.FixValue(self.context, companion["image"])

    def respond(
        self, t_recv: float, utime: int, q: np.ndarray, v: np.ndarray, companion: Optional[dict] = None
    ) -> None:
        """Send the command stamped ``utime`` answering a status checked (with a gripper, first,
        the gripper command for the driver's next tick), and record it."""
        # the hardware simulator's time: Drake's k-th tick is k · T, 1 ulp from utime / 10⁶ at 13 %
        t = round(utime / self.period_us) * self.settings.period if self.period_us else utime / 1e6
        first = self.answered is None
        tau = self.torque(t, q, v, companion)
        if first:  # before the hand-shake's answer: the hardware waits for it up to its start-up
            self.warm_up(t)  # timeout, while a tick waits only its command timeout (0.25 s)
            self.go_realtime()
        self.last_q, self.last_v = q, v
        self.answer = self.terms.command(self.stamp, tau, q, v)
        if self.side is not None:
            # the gripper's driver takes it at its next tick (the hand-shake's: at t = 0), as the
            # one-process run's driver reads the plan's command at each of its ticks
            ahead = 0 if first else self.period_us  # (stamped in the driver's clock)
            self.gripper_answer = pack_wsg_command(
                self.stamp + ahead, self.side.sequence.opening((utime + ahead) / 1e6), self.side.max_force
            )
            self.endpoint.publish_on(WSG_COMMAND_CHANNEL, self.gripper_answer)
        sent = self.endpoint.publish(self.answer)
        self.answered = utime
        record = self.record
        record.commands += 1
        record.compute.append(sent - t_recv)
        record.stamps.append(self.stamp)
        record.received.append(t_recv)
        record.sent.append(sent)
        record.first_t = t if record.first_t is None else record.first_t
        record.last_t = t
        record.t.append(t)
        record.q.append(q)
        record.v.append(v)
        record.tau.append(tau)

    def warm_up(self, t: float) -> None:
        """Before answering the hand-shake: a throwaway run of the controller over a few periods
        from a copy of its context (the hand-shake's inputs), so that every compiled kernel the
        integration and the events call is loaded before the first tick, which must be answered
        within a period (measured: the first real-time ticks answered 1-2 ms late without it,
        five in a row, a hold).  The hardware waits for the hand-shake's answer up to its
        start-up timeout; a later tick only its command timeout (lockstep, 0.25 s: with a
        camera's frames the warm-up and collection took longer than that in a loaded CI run)."""
        scratch = new_simulator(self.simulator.get_system(), self.context.Clone(), self.config)
        scratch.Initialize()
        scratch.AdvanceTo(t + WARM_UP_PERIODS * self.settings.period)
        self.out.Eval(scratch.get_context())
        if self.frames is not None:  # the hand-shake's frame fitted before the first tick
            self.frames.prefetch()

    def go_realtime(self) -> None:
        """After the hand-shake's command and the warm-up, before the answer goes out: the
        collector's start-up objects frozen, then SCHED_FIFO (``process``) for the loop alone.
        Not before: the build, the first command and the warm-up take hundreds of milliseconds of
        CPU, which at a real-time priority would queue a running drive behind this one (a second
        drive started mid-run held the arm as a silent controller that way, instead of being
        named as the second sender)."""
        quiet_collector()
        refused = (request_realtime(self.settings.priority, self.endpoint.threads)
                   if not self.in_memory else None)
        if refused:
            self.warn(refused)

    def finished(self) -> bool:
        """Whether the last tick (t >= duration - 1.5 T) has been answered."""
        return self.quiet_end or (self.answered is not None and self.answered * 1e-6 >= self.end)


def run_drive(
    scenario: Scenario,
    settings: DriveSettings,
    record: DriveRecord,
    url: Optional[str] = None,
    warn: Callable[[str], None] = print,
    lcm=None,
) -> str:
    """Answer the hardware's statuses until the scenario's end (module docstring), recording
    into ``record``; returns the URL used.  ``lcm``: a ``DrakeLcm`` to use instead of one of
    ``url`` (``in_memory``)."""
    loop = _DriveLoop(scenario, settings, record, url, warn, lcm)
    try:
        while True:
            for t_recv, data in loop.wait():
                loop.take(t_recv, data)
            if loop.finished():
                return loop.endpoint.url
    except FrameError as exc:  # a frame the perception's process could not read
        raise DriveFault(f"{exc}; stopped commanding") from None
    finally:
        record.perception = loop.frames.close() if loop.frames is not None else None


__all__ = ["DriveDiagram", "DriveFault", "DriveRecord", "DriveSettings", "drive_series", "drive_summary",
           "run_drive"]
