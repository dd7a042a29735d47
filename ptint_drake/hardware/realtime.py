"""The hardware side's real-time rules (``session.HardwareSession`` without ``--lockstep``): when
each tick's status is due on the wall clock (``TickPacer``) and when the controller counts as
silent (``Silence``).

**Pacing.**  The link paces the simulation itself (the simulator runs unpaced,
``sim_hardware.hardware_scenario``): the tick at t is due at wall time w₀ + (t − t₀) / rate, where
(w₀, t₀) is the first tick after the hand-shake.  (Drake's own pacing counts from the
simulator's ``Initialize``, which holds the hand-shake: the simulator then made up the
hand-shake's 0.4-0.9 s in a burst of statuses at the drive's pace that lasted most of a 3 s run,
measured.)
A tick that finds the hardware more than one period late — its own process stalled — is
*skipped*: the plant steps on under the torque it has, and no status goes out, as a robot's
physics go on while its driver stalls; the next status is the current tick's, not a burst of
catch-up statuses each waiting for an answer.  When a skipped tick does not shrink the lag (the
plant's step alone takes longer than the period: the simulation cannot keep real time), the
clock is set back so that the tick goes out now, and ``rebased`` counts it.

**Silence** is counted in the hardware's own statuses, not in wall time: a status published and
given its full wait with no command of the controller arriving counts one; any command of the
controller — the answer to this status, or a late answer to one of the last ``periods``
statuses — is a sign of life and sets the count back to 0.  A skipped tick publishes nothing
and counts nothing, so a stall of the hardware's own process is never taken for the
controller's silence.  At ``periods`` the controller is silent (the arm is held): a dead
controller is held at its ``periods``-th unanswered status after its last command.
"""

from __future__ import annotations

import time
from typing import Callable, Optional


class TickPacer:
    """When each tick's status goes out (module docstring): ``period`` (s of simulated time),
    ``rate`` (simulated s per wall s); ``clock`` and ``sleep`` are the wall clock's."""

    def __init__(self, period: float, rate: float, clock: Callable[[], float] = time.perf_counter,
                 sleep: Callable[[float], None] = time.sleep):
        self.period, self.rate, self._clock, self._sleep = period, rate, clock, sleep
        self._origin: Optional[tuple[float, float]] = None  # (wall s, simulated s) of the clock's start
        self._behind: Optional[float] = None  # s late at the last tick skipped (None: none skipped)
        self.skipped = 0  # ticks skipped (no status published)
        self.skipped_run_max = 0  # the most ticks skipped in a row
        self._run = 0
        self.rebased = 0  # times the clock was set back (the simulation slower than real time)
        self.late_max = 0.0  # s: the most a published status was late against its due time

    def admit(self, t: float) -> bool:
        """Whether the tick at ``t`` publishes its status (after sleeping until it is due), or is
        skipped (the hardware more than a period late after its own stall)."""
        now = self._clock()
        if self._origin is None:
            self._origin = (now, t)
            return True
        late = now - (self._origin[0] + (t - self._origin[1]) / self.rate)
        if late < 0.0:
            self._sleep(-late)
        elif late > self.period / self.rate:
            if self._behind is None or late < self._behind:  # catching up: skip this tick
                self._behind, self._run = late, self._run + 1
                self.skipped += 1
                self.skipped_run_max = max(self.skipped_run_max, self._run)
                return False
            self._origin, self.rebased, late = (now, t), self.rebased + 1, 0.0  # not catching up
        self._behind, self._run = None, 0
        self.late_max = max(self.late_max, late)
        return True


class Silence:
    """The controller's silence counted in unanswered statuses (module docstring); ``periods``:
    the count that holds the arm."""

    def __init__(self, periods: int):
        self.periods = periods
        self.count = 0  # statuses in a row given their wait without any command
        self.count_max = 0
        self._heard = False  # a command of the controller arrived during this tick's wait

    def start_tick(self) -> None:
        """A status is published: its wait begins."""
        self._heard = False

    def heard(self) -> None:
        """A command of the controller arrived (a sign of life, even a late answer)."""
        self._heard = True

    def end_tick(self, answered: bool) -> bool:
        """The status's wait ended (``answered``: its own command came); True when the controller
        is now silent (``periods`` statuses in a row without a command)."""
        self.count = 0 if answered or self._heard else self.count + 1
        self.count_max = max(self.count_max, self.count)
        return self.count >= self.periods
