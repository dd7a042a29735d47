"""The interception schedule: an ordered list of TBG segments (SPEC section 2.1, 4).

A segment starts its time base generator at ``start`` (absolute time, s) and
must intercept its target at ``start + tf``.  Segment ``i`` is *active* on
``[start_i, start_{i+1})``; after its ``tf`` it holds (stays with the object it
caught) until the next segment starts.  Every block of the interceptor reads the
active segment from time alone, so the whole task is one simulation whose
switches happen at exactly the segment starts.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from scipy.special import beta as beta_function

# One-shot timed events are periodic events whose period exceeds any simulation.
ONE_SHOT_PERIOD = 1.0e9


def gamma_gain(tf: float, beta: float) -> float:
    """γ = Γ(1−β)² / (tf Γ(2−2β)) = B(1−β, 1−β) / tf  (paper eq. 8): the TBG's constant of a
    segment (``tbg``), here so that planning a schedule does not load the compiled kernels."""
    return float(beta_function(1.0 - beta, 1.0 - beta)) / tf


@dataclass(frozen=True)
class Segment:
    """One interception: TBG start time (s), prescribed duration tf (s), shape β."""

    start: float
    tf: float
    beta: float

    @property
    def end(self) -> float:
        """The prescribed interception time start + tf (s)."""
        return self.start + self.tf


class Schedule:
    """Segments in time order, with the lookup of the one active at time t."""

    def __init__(self, segments: Sequence[Segment]):
        if not segments:
            raise ValueError("interceptions: at least one segment is needed")
        for i, seg in enumerate(segments):
            if not 0.0 < seg.beta < 1.0:
                raise ValueError(f"interceptions[{i}].beta: must be in (0, 1), got {seg.beta}")
            if not seg.tf > 0.0:
                raise ValueError(f"interceptions[{i}].tf: must be > 0, got {seg.tf}")
            if i > 0 and seg.start < segments[i - 1].end:
                raise ValueError(
                    f"interceptions[{i}].start: {seg.start} is before the previous "
                    f"segment's interception time {segments[i - 1].end}")
        self.segments = tuple(segments)
        self.starts = tuple(s.start for s in segments)
        self._gammas = tuple(gamma_gain(s.tf, s.beta) for s in segments)  # once per segment
        # rows start, tf, β, γ: the schedule as compiled code reads it (``tbg.tbg_row``)
        self.table = np.array([self.starts, [s.tf for s in segments], [s.beta for s in segments],
                               self._gammas], dtype=float)

    def __len__(self) -> int:
        return len(self.segments)

    def __getitem__(self, i: int) -> Segment:
        return self.segments[i]

    def gamma(self, i: int) -> float:
        """γ = B(1−β, 1−β)/tf of segment i."""
        return self._gammas[i]

    def active(self, t: float) -> int:
        """Index of the segment active at time t; -1 before the first start."""
        return bisect.bisect_right(self.starts, t) - 1

    def hold_end(self, i: int, duration: float) -> float:
        """End of segment i's hold: the next segment's start, or ``duration``."""
        return self.starts[i + 1] if i + 1 < len(self.starts) else duration


def DeclareSegmentStartEvents(system, schedule: Schedule, handler: Callable) -> None:
    """Declare ``handler(context, state)`` on ``system`` as an unrestricted update at
    initialization and at every segment start after t = 0 (a segment starting at 0 is handled
    by the initialization), so the integrator stops exactly at each switch."""
    system.DeclareInitializationUnrestrictedUpdateEvent(handler)
    for start in schedule.starts:
        if start > 0.0:
            system.DeclarePeriodicUnrestrictedUpdateEvent(ONE_SHOT_PERIOD, start, handler)
