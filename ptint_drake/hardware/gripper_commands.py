"""The gripper commands the hardware side receives (``lcmt_schunk_wsg_command``), checked and
kept by the driver's tick they are for (``session.HardwareSession`` with a station's gripper)."""

from __future__ import annotations

from typing import Optional

import numpy as np

from ptint_drake.hardware.link import WSG_COMMAND_CHANNEL, unpack_wsg_command

KEEP, TRIM = 4096, 2048  # commands kept; the oldest dropped when more


class GripperCommands:
    """The gripper commands received: driver's tick utime → (opening m, force N)."""

    def __init__(self) -> None:
        self._by_tick: dict[int, tuple[float, float]] = {}

    def __contains__(self, utime: int) -> bool:
        return utime in self._by_tick

    def opening(self, utime: int) -> Optional[float]:
        """The wanted opening (m) for the driver's tick ``utime``, if its command came."""
        got = self._by_tick.get(utime)
        return None if got is None else got[0]

    def check(self, t: float, data: bytes, max_force: float) -> Optional[tuple[str, str]]:
        """One received command against the checks — decodable, finite, a force within [0,
        ``max_force``], one command per driver tick — and kept; the fault (kind, one-line
        message) when one fails, else None."""
        try:
            utime, opening, force = unpack_wsg_command(data)
        except ValueError as exc:
            return "bad command", f"gripper command rejected at t = {t:.3f} s: {exc}"
        if not (np.isfinite(opening) and np.isfinite(force)):
            return "bad command", f"gripper command rejected at t = {t:.3f} s: not finite"
        if not 0.0 <= force <= max_force * (1 + 1e-9):
            return ("bad command", f"gripper command rejected at t = {t:.3f} s: force {force:.3g} N outside "
                                   f"[0, {max_force:g}] N")
        if utime in self._by_tick and self._by_tick[utime] != (opening, force):
            return ("second sender", f"two different gripper commands for t = {utime * 1e-6:.3f} s at "
                                     f"t = {t:.3f} s: a second sender on {WSG_COMMAND_CHANNEL}")
        self._by_tick[utime] = (opening, force)
        if len(self._by_tick) > KEEP:
            for key in sorted(self._by_tick)[:TRIM]:
                del self._by_tick[key]
        return None
