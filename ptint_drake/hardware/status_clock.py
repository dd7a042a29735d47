"""The drive's clock: a driver's status stamps (``lcmt_iiwa_status.utime``) turned into the
scenario's time.

A robot driver stamps its statuses with a clock of its own, not the scenario's: ``ptint hardware``
starts at 0, Drake's ``IiwaStatusSender`` sends its simulator's time, a real driver may send epoch
µs (1.7·10¹⁵), drake-iiwa-driver sends −1 until its clock runs, and a clock may jump (an NTP step,
a restarted driver).  ``StatusClock.place`` maps each stamp to scenario µs:

- a negative stamp (no clock yet) is placed at the current scenario time (0 before the first
  stamped status): answered, but it does not move the controller's time;
- the first stamp ≥ 0 is the origin, scenario time 0 (``ptint hardware``'s hand-shake at 0: the
  identity);
- a step forward up to ``JUMP_S`` (or ``JUMP_PERIODS`` periods when longer) advances the scenario
  time by the step (statuses lost or a driver of a longer period: the step is time);
- a step backward of at most ``STALE_PERIODS`` periods is a stale status (an older copy arriving
  late): ``None``, skipped;
- any other step is a clock jump: the scenario time advances by one period, the stamp becomes
  the new reference, and ``jumps`` counts it.

The command answering a status carries the status's own stamp (what the driver matches), never
the scenario time.
"""

from __future__ import annotations

from typing import Optional

JUMP_S = 0.5  # s of stamp: a step forward beyond this (and beyond JUMP_PERIODS periods) is a jump
JUMP_PERIODS = 100
STALE_PERIODS = 20  # periods: a step backward within this is a stale status, beyond it a jump


class StatusClock:
    """Scenario µs of each status stamp (module docstring); ``period`` in s."""

    def __init__(self, period: float):
        self.period_us = max(1, int(round(period * 1e6)))
        self.jump_us = max(int(round(JUMP_S * 1e6)), JUMP_PERIODS * self.period_us)
        self.origin: Optional[int] = None  # the first stamp >= 0 (scenario time 0)
        self.last_raw: Optional[int] = None  # the last stamp placed (>= 0)
        self.now_us = 0  # the scenario time of the last status placed
        self.jumps = 0  # clock jumps followed
        self.unset = 0  # statuses with a negative stamp (no clock yet)

    def place(self, raw: int) -> Optional[int]:
        """Scenario µs of the status stamped ``raw``, or None for a stale status (skipped)."""
        if raw < 0:
            self.unset += 1
            return self.now_us
        if self.origin is None:
            self.origin, self.last_raw = raw, raw
            return self.now_us
        step = raw - self.last_raw
        if step < 0 and -step <= STALE_PERIODS * self.period_us:
            return None
        if 0 <= step <= self.jump_us:
            self.now_us += step
        else:
            self.jumps += 1
            self.now_us += self.period_us
        self.last_raw = raw
        return self.now_us

    def summary(self) -> dict:
        """drive.json's ``clock`` block: the origin stamp, the jumps followed, the unset stamps."""
        return {"origin_utime": self.origin, "jumps": self.jumps, "unset_stamps": self.unset}
