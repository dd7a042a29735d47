"""What the hardware side of the link is set to (``LinkSettings``: ``ptint hardware``'s options)
and what it measured (``LinkRecord``: metrics.json's ``hardware`` block), for
``session.HardwareSession``."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ptint_drake.hardware.process import DEFAULT_PRIORITY


@dataclass
class LinkSettings:
    """The hardware side's timing and checks (``ptint hardware``'s options)."""

    period: float  # s: T, the tick of the link and the plant's step
    duration: float  # s of simulated time of the scenario
    lockstep: bool = True
    command_timeout: float = 0.25  # s of wall time a lockstep tick waits for its command
    silent_periods: int = 5  # real time: ticks in a row without a command before the hold
    startup_timeout: float = 10.0  # s of wall time for the first command
    resend: float = 0.005  # s: lockstep re-sends an unanswered status after this wall time
    hold_time: float = 0.5  # s simulated: the hold after a fault before the run ends
    budget: float = 0.8  # real time: the part of T a tick waits for its command
    realtime_rate: float = 1.0
    drop_status: float = 0.0  # a test option: the fraction of status messages not sent
    drop_companion: Optional[float] = None  # a test option: the tick (s) whose gripper status is not sent
    seed: int = 0
    priority: int = DEFAULT_PRIORITY  # real time: SCHED_FIFO priority of the loop (0: none; ``priority``)
    messages: str = "iiwa"  # the arm's message set and channels (``arm_messages.MESSAGES``)


@dataclass
class LinkRecord:
    """What the hardware side measured of the link."""

    rtt: list = field(default_factory=list)  # s wall: status published → its command received
    tick_wall: list = field(default_factory=list)  # perf_counter of each tick's first publish
    tick_time: list = field(default_factory=list)  # simulated t of each tick
    # per tick (``link_series``), perf_counter s: the status handed to LCM, its answer handled
    # (NaN: none within the tick's wait), the tick's wait ended
    tick_sent: list = field(default_factory=list)
    tick_answered: list = field(default_factory=list)
    tick_waited: list = field(default_factory=list)
    late_utime: list = field(default_factory=list)  # answers after their tick: the status's utime
    late_wall: list = field(default_factory=list)  # ... and when they were handled (perf_counter s)
    statuses: int = 0  # status messages published (re-sends included)
    dropped: int = 0  # status messages not sent (``drop_status``)
    companions_dropped: int = 0  # gripper statuses not sent (``drop_companion``)
    resends: int = 0
    accepted: int = 0
    duplicates: int = 0  # a command repeated for its status (an answer to a re-sent status)
    late: int = 0  # real time: ticks whose command did not arrive within the budget
    late_run_max: int = 0  # real time: the most ticks in a row without a command
    late_commands: int = 0  # commands that arrived after their tick
    gripper_commands: int = 0  # gripper commands taken (a station with a gripper)
    last_command_t: Optional[float] = None  # simulated t of the last command accepted
    last_heard_t: Optional[float] = None  # simulated t of the tick the last command (late ones too) came in
    frames_sent: int = 0  # depth frames published (a station with a camera; re-sends not counted)
    fault: Optional[str] = None
    fault_time: Optional[float] = None
    fault_kind: Optional[str] = None
    stop_signal: Optional[int] = None  # SIGINT or SIGTERM received: the run was stopped (held)


def link_series(record: LinkRecord) -> dict:
    """The link's per-tick wall times as arrays (series.npz's ``link_*`` entries): with the drive's
    (``drive_series``: ``stamp``, ``recv_wall``, ``sent_wall``) they say on which side a late tick
    was late (``perf_counter`` is one clock for both processes: Linux's ``CLOCK_MONOTONIC``)."""
    return {
        "link_tick_t": np.asarray(record.tick_time, dtype=float),
        "link_tick_sent": np.asarray(record.tick_sent, dtype=float),
        "link_tick_answered": np.asarray(record.tick_answered, dtype=float),
        "link_tick_waited": np.asarray(record.tick_waited, dtype=float),
        "link_late_utime": np.asarray(record.late_utime, dtype=np.int64),
        "link_late_wall": np.asarray(record.late_wall, dtype=float),
    }
