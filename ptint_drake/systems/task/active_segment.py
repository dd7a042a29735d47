"""``ActiveSegment``: [index, start, tf] of the segment active at time t (a schedule as a port).

Output ``segment`` (3): the index of the active segment (the first one before its start: it is
what comes), its start time (s) and its prescribed duration tf (s), so that a controller can
know its deadline start + tf.  Read from time alone, like every block of the interceptor
(``systems.task.schedule``).
"""

from __future__ import annotations

from pydrake.systems.framework import BasicVector, Context, LeafSystem

from ptint_drake.systems.task.schedule import Schedule

SIZE = 3


class ActiveSegment(LeafSystem):
    """Output ``segment`` = [index, start, tf] of ``schedule``'s active segment."""

    def __init__(self, schedule: Schedule):
        super().__init__()
        self._schedule = schedule
        self.DeclareVectorOutputPort("segment", SIZE, self._calc,
                                     prerequisites_of_calc={self.time_ticket()})

    def _calc(self, context: Context, output: BasicVector) -> None:
        i = max(self._schedule.active(context.get_time()), 0)
        segment = self._schedule[i]
        output.SetFromVector([float(i), segment.start, segment.tf])
