"""What ``ptint drive`` is set to (``DriveSettings``: its options) and what it received and sent
(``DriveRecord``), written as drive.json (``drive_summary``) and drive_series.npz (``drive_series``)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from ptint_drake.hardware.link import COMMAND_CHANNEL, STATUS_CHANNEL, spread
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


@dataclass
class DriveRecord:
    """What the drive received and sent."""

    statuses: int = 0
    repeats: int = 0  # statuses received again (re-sent by the hardware)
    stale: int = 0  # statuses older than one already answered
    gaps: int = 0  # ticks skipped between two statuses (lost or not sent)
    commands: int = 0
    compute: list = field(default_factory=list)  # s wall: status received → command sent
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


def drive_summary(record: DriveRecord, settings: DriveSettings, url: str) -> dict:
    """drive.json: what the drive received and sent."""
    return {
        "url": url,
        "status_channel": STATUS_CHANNEL,
        "subscribed_channels": list(record.channels),
        "command_channel": COMMAND_CHANNEL,
        "period": settings.period,
        "statuses_received": record.statuses,
        "statuses_repeated": record.repeats,
        "statuses_stale": record.stale,
        "ticks_missing": record.gaps,
        "commands_sent": record.commands,
        "first_t": record.first_t,
        "last_t": record.last_t,
        "compute_ms": spread(record.compute, 1e3),
        "commands_clipped": record.clipped,
        "scheduler": scheduler_name(),
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
    }
