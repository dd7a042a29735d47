"""A driver with a clock of its own, for the drive's clock tests: ``ptint hardware`` and ``ptint
drive`` as two threads, each on its own in-memory LCM (``memq://``), with a relay thread between
them that restamps every status by a driver clock (epoch µs, −1 before the clock runs, a jump)
and puts the hardware's stamps back on the commands.  Everything else crosses unchanged, so a
drive that follows the clock gives the plain pair's run exactly."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path
from typing import Callable

from drake import lcmt_iiwa_command, lcmt_iiwa_status
from pydrake.lcm import DrakeLcm

from ptint_drake.hardware.drive import DriveRecord, DriveSettings, drive_summary, run_drive
from ptint_drake.hardware.link import COMMAND_CHANNEL, MEMQ_LOCK, STATUS_CHANNEL
from ptint_drake.hardware.session import LinkSettings
from ptint_drake.hardware.sim_hardware import run_hardware

# (the hardware's stamp, the status's measured positions, whether that stamp was seen before
# with other positions) -> the driver's stamp
Clock = Callable[[int, tuple, bool], int]


def relay(hardware: DrakeLcm, drive: DrakeLcm, clock: Clock, stop: threading.Event) -> None:
    """Forward statuses hardware → drive restamped by ``clock``, commands drive → hardware with
    the hardware's stamp back, until ``stop``."""
    back: dict[int, int] = {}
    first_q: dict[int, tuple] = {}

    def status(data: bytes) -> None:
        m = lcmt_iiwa_status.decode(data)
        q = tuple(m.joint_position_measured)
        again = first_q.setdefault(m.utime, q) != q
        stamp = clock(m.utime, q, again)
        back[stamp] = m.utime
        m.utime = stamp
        drive.Publish(STATUS_CHANNEL, m.encode())

    def command(data: bytes) -> None:
        m = lcmt_iiwa_command.decode(data)
        m.utime = back[m.utime]
        hardware.Publish(COMMAND_CHANNEL, m.encode())

    hardware.Subscribe(STATUS_CHANNEL, status)
    drive.Subscribe(COMMAND_CHANNEL, command)
    while not stop.is_set():
        with MEMQ_LOCK:
            handled = hardware.HandleSubscriptions(0) + drive.HandleSubscriptions(0)
        if not handled:
            time.sleep(5e-5)


def run_relayed_pair(scenario, settings: LinkSettings, out: Path, clock: Clock) -> tuple[dict, dict]:
    """(the hardware's metrics.json, the drive's drive.json) of a lockstep pair whose statuses
    reach the drive restamped by ``clock``."""
    a, b = DrakeLcm("memq://"), DrakeLcm("memq://")
    result: dict = {}
    stop = threading.Event()

    def hardware() -> None:
        try:
            result["metrics"] = run_hardware(scenario, settings, out, warn=lambda m: None, lcm=a)
        except Exception as exc:  # noqa: BLE001  (handed to the test's thread)
            result["error"] = exc

    drive = DriveSettings(period=settings.period, duration=settings.duration,
                          startup_timeout=settings.startup_timeout)
    record = DriveRecord()
    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    threads = [threading.Thread(target=hardware, daemon=True),
               threading.Thread(target=relay, args=(a, b, clock, stop), daemon=True)]
    try:
        for thread in threads:
            thread.start()
        url = run_drive(scenario, drive, record, warn=lambda m: None, lcm=b)
        threads[0].join()
    finally:
        stop.set()
        sys.setswitchinterval(interval)
    if "error" in result:
        raise result["error"]
    return result["metrics"], drive_summary(record, drive, url)
