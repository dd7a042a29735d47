"""What the two link processes ask of their own process: real-time scheduling where the system
permits it (``request_realtime``), a garbage collector that leaves the start-up's objects alone
(``quiet_collector``), and SIGINT / SIGTERM as a stop that holds the arm (``stop_on_signals``).

A control loop at 1 kHz answers each status within a period; the hardware side holds the arm
after ``LinkSettings.silent_periods`` ticks (5 ms at 1 kHz) without a command.  Under Linux's
default scheduler a process that wakes on a busy machine may wait several milliseconds for a
core, so ``ptint drive`` and the real-time ``ptint hardware`` ask for ``SCHED_FIFO``
(``os.sched_setscheduler``), as a robot's control PC runs its loop (measured on the 2-core
virtual machine, curve_b075_tf15: with neither this nor the drive's warm-up, 4 of 5 clean
real-time runs at load 3.6 held on 5 late ticks; with both, 0 of 10 at load 0.5 and 0 of 3 at
load 3.9 — a sleep under SCHED_FIFO still overshoots by up to 8 ms there, when the host pauses
the virtual CPU).  That needs ``CAP_SYS_NICE`` (root, or an ``rtprio`` entry in
``/etc/security/limits.conf``); without it the process keeps the default scheduler and says so
in one warning.  Both loops sleep in ``select`` between messages, so a FIFO priority never spins
a core; the kernel's real-time throttling (``sched_rt_runtime_us``) leaves the rest of the
machine 5 % in any case.
"""

from __future__ import annotations

import gc
import os
import signal
import threading
from contextlib import contextmanager
from typing import Iterable, Optional

DEFAULT_PRIORITY = 10  # SCHED_FIFO priority (1-99); low enough to leave the kernel's threads above it


def request_realtime(priority: int, threads: Iterable[int] = ()) -> Optional[str]:
    """Ask for ``SCHED_FIFO`` at ``priority`` for the calling thread and for ``threads`` (their
    thread ids: LCM's receive thread, ``link.Endpoint.threads``) (0: keep the default scheduler);
    returns a warning when the system refused, else None.  Linux schedules each thread on its
    own: every message the loop waits for passes through LCM's receive thread first, which at
    the default policy waited for a core behind the machine's other work (measured: answers
    handed to LCM 0.3 ms after the status were handled 1.2 ms after it, a hold)."""
    if priority <= 0 or not hasattr(os, "sched_setscheduler"):
        return None
    try:
        for tid in (0, *threads):
            os.sched_setscheduler(tid, os.SCHED_FIFO, os.sched_param(priority))
    except ProcessLookupError:  # (a thread that has ended: nothing to schedule)
        pass
    except (PermissionError, OSError) as exc:
        return (f"real-time scheduling (SCHED_FIFO {priority}) refused ({exc.strerror or exc}): on a "
                f"loaded machine late commands may hold the arm; run as root, give the user an "
                f"rtprio limit, or pass --priority 0 to silence this")
    return None


def scheduler_name(tid: int = 0) -> str:
    """The scheduling policy of the thread ``tid`` (0: the calling one) as metrics report it:
    ``SCHED_FIFO 10`` or ``default`` (``gone``: a thread that has ended)."""
    if not hasattr(os, "sched_getscheduler"):
        return "default"
    try:
        if os.sched_getscheduler(tid) == os.SCHED_FIFO:
            return f"SCHED_FIFO {os.sched_getparam(tid).sched_priority}"
    except ProcessLookupError:
        return "gone"
    return "default"


def new_threads(before: set) -> list[int]:
    """The ids of this process's threads not in ``before`` (``thread_ids()`` taken earlier)."""
    return sorted(thread_ids() - before)


def thread_ids() -> set:
    """The ids of this process's threads (Linux: ``/proc/self/task``; elsewhere none)."""
    try:
        return {int(name) for name in os.listdir("/proc/self/task")}
    except OSError:
        return set()


def quiet_collector() -> None:
    """Before a real-time loop: collect once, then move every object alive into the collector's
    permanent generation (``gc.freeze``), so that a later full collection does not walk the
    interpreter's, pydrake's and numba's hundreds of thousands of start-up objects: such a pass
    takes milliseconds, several control periods of an arm's link.  The collector stays on for
    what the loop itself allocates."""
    gc.collect()
    gc.freeze()


@contextmanager
def stop_on_signals(session):
    """While the block runs, SIGINT and SIGTERM ask ``session`` (a ``session.HardwareSession``) to
    stop (``request_stop``): the arm is held for ``hold_time`` and the run ends with its metrics
    written, as after any fault.  The
    first signal puts the previous handlers back, so a second one acts as it did before (Ctrl-C
    twice: ``KeyboardInterrupt``).  Outside the main thread (``in_memory``'s hardware thread)
    nothing is installed: Python delivers signals to the main thread only."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}

    def handler(signum, _frame):
        for sig, old in previous.items():
            signal.signal(sig, old)
        session.request_stop(signum)

    for sig in (signal.SIGINT, signal.SIGTERM):
        previous[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, old in previous.items():
            if signal.getsignal(sig) is handler:
                signal.signal(sig, old)
