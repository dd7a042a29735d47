"""Cache entries that hold a numpy vector, shared by several output ports.

Drake caches each output port on its own; when several ports (and the time
derivatives) come from one computation, a cache entry computes it once per
change of its prerequisites and the ports read slices of it.
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import ValueProducer


def DeclareVectorCache(system, description: str, size: int,
                       calc: Callable[[object], np.ndarray], prerequisites_of_calc):
    """Declare on ``system`` a cache entry whose value is ``calc(context)``.

    Returns a function ``eval(context) -> np.ndarray`` (read-only use).
    """
    def allocate():
        return AbstractValue.Make(np.zeros(size))

    def do_calc(context, value):
        value.set_value(calc(context))

    entry = system.DeclareCacheEntry(
        description, ValueProducer(allocate=allocate, calc=do_calc),
        prerequisites_of_calc=prerequisites_of_calc)
    return entry.Eval
