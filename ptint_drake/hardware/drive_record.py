"""What ``ptint drive`` is set to (``DriveSettings``: its options) and what it received and sent
(``DriveRecord``), written as drive.json (``drive_summary``) and drive_series.npz (``drive_series``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ptint_drake.hardware.arm_messages import arm_messages
from ptint_drake.hardware.link import spread
from ptint_drake.hardware.process import DEFAULT_PRIORITY, scheduler_name


@dataclass
class DriveSettings:
    """The drive side's timeouts (``ptint drive``'s options)."""

    period: float
    duration: float
    startup_timeout: float = 10.0  # s wall for the first status
    status_timeout: float = 0.5  # s wall without a status once running
    priority: int = DEFAULT_PRIORITY  # SCHED_FIFO priority of the loop (0: none; ``hardware.priority``)
    driver_mode: str = "torque"  # what the driver adds to a command (``driver_modes.DRIVER_MODES``)
    messages: str = "iiwa"  # the arm's message set and channels (``arm_messages.MESSAGES``)


@dataclass
class DriveRecord:
    """What the drive received and sent."""

    statuses: int = 0
    repeats: int = 0  # statuses received again (re-sent by the hardware)
    stale: int = 0  # statuses older than one already answered
    gaps: int = 0  # ticks skipped between two statuses (lost or not sent)
    companions_lost: int = 0  # statuses not answered: a companion of theirs lost (``companions``)
    commands: int = 0
    compute: list = field(default_factory=list)  # s wall: status received → command sent
    stamps: list = field(default_factory=list)  # the answered statuses' stamps (the driver's utime)
    received: list = field(default_factory=list)  # perf_counter s: each answered status handled
    sent: list = field(default_factory=list)  # perf_counter s: its command handed to LCM
    perception: Optional[dict] = None  # a perception in its own process: its fits' and waits' times
    clipped: int = 0  # commands clipped to the actuators' effort limits
    url: Optional[str] = None  # the LCM URL in use
    channels: list = field(default_factory=list)  # the channels subscribed to
    first_t: Optional[float] = None
    last_t: Optional[float] = None
    t: list = field(default_factory=list)
    q: list = field(default_factory=list)
    v: list = field(default_factory=list)
    tau: list = field(default_factory=list)
    clock: Optional[object] = None  # the ``status_clock.StatusClock`` of the driver's stamps
    threads: list = field(default_factory=list)  # LCM's receive threads (``link.Endpoint.threads``)


def drive_summary(record: DriveRecord, settings: DriveSettings, url: str) -> dict:
    """drive.json: what the drive received and sent."""
    messages = arm_messages(settings.messages)
    return {
        "url": url,
        "messages": messages.name,
        "status_channel": messages.status_channel,
        "subscribed_channels": list(record.channels),
        "command_channel": messages.command_channel,
        "period": settings.period,
        "statuses_received": record.statuses,
        "statuses_repeated": record.repeats,
        "statuses_stale": record.stale,
        "ticks_missing": record.gaps,
        "companions_lost": record.companions_lost,
        "commands_sent": record.commands,
        "first_t": record.first_t,
        "last_t": record.last_t,
        "compute_ms": spread(record.compute, 1e3),
        "ticks_over_period": int(np.count_nonzero(np.asarray(record.compute) > settings.period)),
        "perception": record.perception,
        "commands_clipped": record.clipped,
        "scheduler": scheduler_name(),
        "receive_thread_scheduler": [scheduler_name(tid) for tid in record.threads],
        "driver_mode": settings.driver_mode,
        "clock": record.clock.summary() if record.clock is not None else None,
    }


def drive_series(record: DriveRecord) -> dict:
    """The statuses received and commands sent, as arrays (drive_series.npz)."""
    return {
        "t": np.asarray(record.t),
        "q": np.asarray(record.q),
        "v": np.asarray(record.v),
        "tau": np.asarray(record.tau),
        "compute": np.asarray(record.compute),  # s wall: status received → command sent
        # perf_counter s (CLOCK_MONOTONIC: the hardware's ``link_*`` series share the clock)
        "stamp": np.asarray(record.stamps, dtype=np.int64),
        "recv_wall": np.asarray(record.received, dtype=float),
        "sent_wall": np.asarray(record.sent, dtype=float),
    }
