"""The hardware and the drive in one process over an in-memory LCM (``memq://``): where no private
network namespace can be made (a container without user namespaces), the same two sides run as
two threads of this process sharing one ``DrakeLcm("memq://")`` — the same messages, checks and
timing records, with no packet on any network.  The round trip then includes the threads'
turns at Python's interpreter lock (``sys.setswitchinterval`` is lowered while they run), so it
shows the link's logic, not a two-process latency; lockstep results do not depend on it.

``run_pair`` runs both and returns the hardware's metrics and the drive's summary.
"""

from __future__ import annotations

import sys
import threading
from pathlib import Path
from typing import Optional

from pydrake.lcm import DrakeLcm

from ptint_drake.config.schema import Scenario
from ptint_drake.hardware.drive import DriveRecord, DriveSettings, drive_summary, run_drive
from ptint_drake.hardware.session import LinkSettings
from ptint_drake.hardware.sim_hardware import run_hardware

SWITCH_INTERVAL = 1e-4  # s: the interpreter's thread switch interval while both sides run


def run_pair(scenario: Scenario, settings: LinkSettings, out: Path, lcm: Optional[DrakeLcm] = None
             ) -> tuple[dict, dict]:
    """(metrics.json of the hardware, drive.json's summary) of ``scenario`` run as hardware (a
    thread) and drive (this thread) over one in-memory LCM (``lcm``, a ``memq://`` one, e.g. with
    a listener of its own; default a new one); the hardware's outputs in ``out``."""
    lcm = lcm if lcm is not None else DrakeLcm("memq://")
    result: dict = {}

    def hardware() -> None:
        try:
            result["metrics"] = run_hardware(scenario, settings, out, warn=lambda m: None, lcm=lcm)
        except Exception as exc:  # noqa: BLE001  (handed to the caller's thread)
            result["error"] = exc

    drive = DriveSettings(
        period=settings.period, duration=settings.duration, startup_timeout=settings.startup_timeout,
        messages=settings.messages,
    )
    record = DriveRecord()
    interval = sys.getswitchinterval()
    sys.setswitchinterval(SWITCH_INTERVAL)
    thread = threading.Thread(target=hardware, name="hardware", daemon=True)
    try:
        thread.start()
        url = run_drive(scenario, drive, record, warn=lambda m: None, lcm=lcm)
        thread.join()
    finally:
        sys.setswitchinterval(interval)
    if "error" in result:
        raise result["error"]
    return result["metrics"], drive_summary(record, drive, url)
