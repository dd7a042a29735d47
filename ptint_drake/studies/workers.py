"""The local worker processes of ``studies.runner``: how one is started (``fork_is_safe``,
``start_method``), what it runs (``worker_main``: tasks in, results out over a pipe, SIGINT
ignored, SIGTERM removing what its task was staging, dying with its parent) and its handle in
the parent (``Worker``).  ``studies.runner``'s docstring gives the pool's rules."""

from __future__ import annotations

import _thread
import multiprocessing
import os
import signal
import sys
import threading
import traceback

from ptint_drake.outputs.folder import remove_live_stages


def rss_mb() -> float:
    """Resident set of this process now (MB); 0 where /proc is missing."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (OSError, ValueError, IndexError):
        return 0.0


def _stop_worker(signum, frame):
    """A local worker's SIGTERM (the parent stopping it after Ctrl-C or an error, or the
    parent's death): remove what its task was staging, then exit without unwinding."""
    remove_live_stages()
    os._exit(128 + signum)


# set beside PYTHONSAFEPATH while ``start_forkserver`` starts the server: its workers unset both
SAFE_PATH_MARK = "_PTINT_FORKSERVER_SAFE_PATH"


def worker_main(conn, fn):
    """A local worker: tasks ``(index, args)`` in, ``(index, ok, value, rss_mb)`` out.

    SIGINT is ignored (the parent handles Ctrl-C); SIGTERM is ``_stop_worker``.  A worker of a
    forkserver ``start_forkserver`` started drops the server's ``PYTHONSAFEPATH`` from its
    environment (the processes its task starts get the caller's usual path)."""
    if os.environ.pop(SAFE_PATH_MARK, None):
        os.environ.pop("PYTHONSAFEPATH", None)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    signal.signal(signal.SIGTERM, _stop_worker)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT, signal.SIGTERM})
    _die_with_parent()
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        index, args = message
        try:
            reply = (index, True, fn(*args))
        except BaseException as exc:  # noqa: BLE001  (sent to the parent, re-raised there)
            exc.add_note("in a worker process:\n" + "".join(traceback.format_exc()).rstrip())
            reply = (index, False, exc)
        try:
            conn.send(reply + (rss_mb(),))
        except Exception as exc:  # noqa: BLE001  (an unpicklable result or exception)
            conn.send((index, False, RuntimeError(f"task {index}: cannot send its result back: "
                                                  f"{exc!r}: {reply[2]!r}"[:500]), rss_mb()))


def _die_with_parent():
    """Linux: SIGTERM this worker when the parent dies (even by SIGKILL)."""
    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes  # noqa: PLC0415

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


class Worker:
    """A local worker process running ``worker_main`` for ``fn``, and its end of the pipe; ``task``:
    the index in flight (None: idle), ``done``: the tasks it finished."""

    def __init__(self, ctx, fn):
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=worker_main, args=(child, fn), daemon=True,
                                   name="ptint-worker")
        # SIGINT blocked across the fork: the child ignores it before it can arrive, and a
        # Ctrl-C meanwhile is delivered to the parent when unblocked below.
        old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        try:
            self.process.start()
        finally:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)
        child.close()
        self.task = None  # index in flight
        self.done = 0

    def send(self, index, args):
        self.conn.send((index, args))
        self.task = index

    def stop(self):
        """Ask to exit (between tasks)."""
        try:
            self.conn.send(None)
        except OSError:
            pass

    def kill(self):
        if self.process.is_alive():
            self.process.terminate()


def fork_is_safe() -> bool:
    """Whether a ``fork`` of this process is provably safe: no Python thread runs but the
    calling one, so no lock can be held by a thread the child would not have.  Both counts
    matter: ``threading.active_count`` sees the threads of ``threading`` (a Dask client's
    event loop, a Jupyter kernel's), ``_thread._count`` also those started with ``_thread``
    (pytest-xdist's execnet I/O thread, which ``threading`` never sees).  They are what
    Python >= 3.12 counts when it warns that a fork "may lead to deadlocks in the child".
    Native threads are not Python threads and do not count: OpenBLAS's pool (started by
    ``import numpy``) re-arms itself across a fork (``pthread_atfork``), and Drake's Meshcat
    server threads are checked for separately (``report.run_outputs.can_fork``)."""
    count = getattr(_thread, "_count", lambda: 0)  # threads started here, the main one not counted
    return ("fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1
            and count() == 0)


def start_method(fn) -> str:
    """``fork`` when the fork is safe (``fork_is_safe``: this process runs one Python thread,
    the command line's case), else ``forkserver``: a fork copies only the calling thread, so
    a lock another thread holds (a Dask client's event loop, a Jupyter kernel's, pytest-xdist's
    I/O thread) stays locked in the child forever; the forkserver is a fresh single-threaded
    process that forks the workers instead.  ``spawn`` where neither exists.  A ``fn`` defined
    in ``__main__`` (a notebook cell, a script) is forked whatever the threads: a forkserver
    child could not import it (Python warns about that fork, rightly)."""
    methods = multiprocessing.get_all_start_methods()
    in_main = getattr(fn, "__module__", None) == "__main__"
    if "fork" in methods and (fork_is_safe() or in_main):
        return "fork"
    return "forkserver" if "forkserver" in methods else "spawn"


def start_forkserver(ctx, preload: list) -> None:
    """Start this process's forkserver (once: later calls find it running) with ``preload``
    imported from where this process imports it.  CPython starts the server as ``python -c`` in
    this process's working folder and, up to 3.13 at least, does not apply the ``sys.path`` it
    is given before importing the preload (``multiprocessing.forkserver.main``), so the working
    folder comes first: inside a source tree the server imported the tree's ``ptint_drake``
    rather than the installed one, and with it numba's cache of the tree, empty on a
    non-editable install (measured: pytest-xdist on Drake 1.51.1, .ci/run's oldest end, compiled
    every kernel again there).  ``PYTHONSAFEPATH`` (Python >= 3.11; ignored by 3.10) keeps the
    working folder off the server's path; it is set only while the server starts."""
    from multiprocessing import forkserver  # noqa: PLC0415

    ctx.set_forkserver_preload(preload)
    if "PYTHONSAFEPATH" in os.environ:
        forkserver.ensure_running()
        return
    os.environ.update({"PYTHONSAFEPATH": "1", SAFE_PATH_MARK: "1"})
    try:
        forkserver.ensure_running()
    finally:
        os.environ.pop("PYTHONSAFEPATH", None)
        os.environ.pop(SAFE_PATH_MARK, None)
