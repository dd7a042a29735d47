"""The one task runner every study uses (sweep, robust, compare, tune).

    results = run_tasks(fn, tasks, workers=N)            # local worker processes
    results = run_tasks(fn, tasks, dask="tcp://host:8786")  # a Dask scheduler
    results = run_tasks(fn, tasks, executor=pool)         # any concurrent.futures.Executor

``fn(*task)`` is called once per task (``fn`` must be a module-level function and the
tasks picklable: Drake diagrams do not pickle, send scenario *text*); the results come
back in task order, whatever the order in which they finished, so a study gives the
same numbers with 1 worker, N workers or on a cluster.

Local workers (the default) are this module's own small pool, not a
``ProcessPoolExecutor``:

- forked on Linux when the calling process runs no Python thread but its own, as the
  command line does (``fork_is_safe``; a fork from a parent that has imported Drake starts
  in ~10 ms), from a forkserver when it runs more (a Jupyter kernel, a Dask client,
  pytest-xdist's I/O thread: a forked child would inherit their locks held; the forkserver
  imports ``fn``'s module, pydrake with it, once, ~2 s, and forks each worker from
  itself) unless ``fn`` is defined in ``__main__`` (a notebook cell), spawned elsewhere;
- one task in flight per worker (dispatch on completion: a pipe round trip costs
  ~0.1 ms against ≥ 0.1 s per simulation), so nothing is submitted up front;
- recycled after ``max_tasks_per_child`` tasks (default ``MAX_TASKS_PER_CHILD``):
  the diagram of a simulation (and the plant in it) is never freed, on Drake 1.51.1 and
  1.58.0 alike: its LeafSystems that hold a Drake cache entry (``systems.task.cache``) are in a
  reference cycle through C++ that Python's garbage collector cannot see (1.51.1 keeps
  every Python LeafSystem alive, 1.58.0 only those).  Measured over 120 runs in one process:
  ≈ 1.05 MB per simulation of ``curve_b075_tf15``, ≈ 1.55 MB per ``ptint robust`` sample
  of it (camera and estimator included), on both (tests/e2e/test_runner.py).  A new
  worker is forked from the parent, which never builds a diagram, so a worker's resident
  set stays below its start plus 50 samples' worth whatever the sample count.  The stdlib's
  ``max_tasks_per_child`` refuses ``fork`` (its executor has a management thread);
  this pool has no thread, so it forks safely;
- Ctrl-C: the workers ignore SIGINT (the terminal sends it to the whole process
  group); the parent gets ``KeyboardInterrupt``, terminates every worker (SIGTERM,
  then SIGKILL after 1.5 s), waits for them and re-raises — well under a second.  A
  worker's SIGTERM handler removes the folders its task was staging
  (``outputs.remove_live_stages``) and exits at once: nothing is left half-written, and no
  exception is raised into whatever the task was running (a ctypes callback, e.g. numba's
  cache, would print it and carry on);
- a worker that dies (e.g. killed by the OOM killer) raises ``WorkerDied``.

With ``dask=ADDRESS`` a ``distributed.Client`` is opened on that scheduler (and
closed at the end), with an executor, a window of 2 × (worker threads) tasks in
flight; on Ctrl-C the pending tasks are cancelled.  An unreachable scheduler raises
``SchedulerUnreachable``.  Dask workers are long-lived: to bound the leak above
there, start them with ``--lifetime`` (e.g. ``dask worker ADDR --lifetime 30m
--lifetime-restart``).

``progress(done, total, index, result)`` is called in the calling process as each
result arrives.  ``stats`` (a dict, optional) receives ``workers``,
``worker_starts``, ``worker_rss_mb`` (largest resident set of a worker measured
after a task), ``worker_rss_mb_by_task`` (per task, in task order) and, for local
workers, ``start_method``.
"""

from __future__ import annotations

import concurrent.futures as cf
import functools
import multiprocessing
import os
from multiprocessing.connection import wait as wait_any

from ptint_drake.controllers import plugin
from ptint_drake.studies.workers import Worker, rss_mb, start_forkserver, start_method

MAX_TASKS_PER_CHILD = 50
DASK_CONNECT_TIMEOUT_S = 5.0


class SchedulerUnreachable(ConnectionError):
    """The Dask scheduler given with ``dask=`` cannot be reached."""


class WorkerDied(RuntimeError):
    """A local worker process ended without returning its task's result."""


def _with_plugin_folders(fn, folders: tuple):
    """``fn`` that looks for plugin controllers in ``folders`` (the scenario file's, which the
    study hands over) in whatever process runs it, Dask workers included."""
    if not folders:
        return fn
    return functools.partial(_in_plugin_folders, fn, tuple(folders))


def _in_plugin_folders(fn, folders, *args):
    with plugin.searching(folders):
        return fn(*args)


def _call(fn, args):
    """Run one task where it is executed; returns (result, RSS after it in MB)."""
    result = fn(*args)
    return result, rss_mb()


def run_tasks(fn, tasks, *, workers: int | None = None, dask: str | None = None,
              executor: cf.Executor | None = None, progress=None,
              max_tasks_per_child: int | None = MAX_TASKS_PER_CHILD, window: int | None = None,
              stats: dict | None = None, folders: tuple = ()) -> list:
    """``[fn(*t) for t in tasks]`` computed in parallel; see the module docstring.  ``folders``:
    where a plugin controller's module is looked for in each task (``LoadedScenario.folders``).

    At most one of ``dask`` and ``executor``; neither: ``workers`` local processes
    (default: CPU count).  ``executor`` is used as given and left open.  ``window``
    bounds the tasks in flight on an executor/Dask (default 2 × workers).
    ``max_tasks_per_child`` (local pool only; ``None``: never recycle).
    """
    tasks = [tuple(t) for t in tasks]
    fn = _with_plugin_folders(fn, folders)
    if dask is not None and executor is not None:
        raise ValueError("give dask= or executor=, not both")
    if workers is not None and workers < 1:
        raise ValueError(f"workers must be >= 1, got {workers}")
    stats = {} if stats is None else stats
    stats.update(workers=0, worker_starts=0, worker_rss_mb=0.0, worker_rss_mb_by_task=[])
    if not tasks:
        return []
    if executor is not None:
        n = workers or getattr(executor, "_max_workers", None) or os.cpu_count() or 1
        return _run_executor(executor, fn, tasks, window or 2 * n, progress, stats, n)
    if dask is not None:
        return _run_dask(dask, fn, tasks, window, progress, stats)
    return _run_local(fn, tasks, workers or os.cpu_count() or 1, progress, max_tasks_per_child, stats)


# --------------------------------------------------------------------------- executors, Dask

def _run_executor(executor, fn, tasks, window, progress, stats, n_workers) -> list:
    n = len(tasks)
    results = [None] * n
    rss = [0.0] * n
    stats["workers"] = n_workers
    running: dict = {}
    submitted = done = 0
    try:
        while done < n:
            while submitted < n and len(running) < window:
                running[executor.submit(_call, fn, tasks[submitted])] = submitted
                submitted += 1
            finished, _ = cf.wait(running, return_when=cf.FIRST_COMPLETED)
            for future in sorted(finished, key=running.get):
                i = running.pop(future)
                results[i], rss[i] = future.result()
                done += 1
                if progress:
                    progress(done, n, i, results[i])
    except BaseException:
        for future in running:
            future.cancel()
        raise
    stats["worker_rss_mb_by_task"] = rss
    stats["worker_rss_mb"] = max(rss)
    return results


def _run_dask(address, fn, tasks, window, progress, stats) -> list:
    try:
        import distributed  # noqa: PLC0415
    except ImportError:
        raise SchedulerUnreachable("dask: the 'distributed' package is not installed") from None
    try:
        # a malformed address or unknown host fails here, fast; inside Client() it would leave a
        # half-built client whose __del__ blocks 10 s at exit and prints a traceback
        distributed.comm.resolve_address(address)
        client = distributed.Client(address, timeout=DASK_CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        detail = " ".join(str(exc).split())[:200] or type(exc).__name__
        raise SchedulerUnreachable(f"cannot reach the Dask scheduler at {address}: {detail}") from None
    try:
        threads = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()) or 1
        executor = client.get_executor(pure=False)
        return _run_executor(executor, fn, tasks, window or 2 * threads, progress, stats, threads)
    finally:
        client.close(timeout=2)


# --------------------------------------------------------------------------- local pool

def _run_local(fn, tasks, workers, progress, max_tasks_per_child, stats) -> list:
    return _LocalRun(fn, tasks, max_tasks_per_child, stats).run(workers, progress)


class _LocalRun:
    """One ``run_tasks`` on this module's pool: the workers, the next task to send, the results."""

    def __init__(self, fn, tasks, max_tasks_per_child, stats):
        method = start_method(fn)
        stats["start_method"] = method
        self.ctx = multiprocessing.get_context(method)
        if method == "forkserver":
            # the server imports fn's module (pydrake with it) once when it starts, and each
            # worker forked from it has it already: ~10 ms a worker instead of ~2 s
            inner = fn.args[0] if isinstance(fn, functools.partial) else fn  # _with_plugin_folders
            module = getattr(inner, "__module__", None)
            start_forkserver(self.ctx, [__name__] + ([module] if module else []))
        self.fn, self.tasks, self.max_tasks, self.stats = fn, tasks, max_tasks_per_child, stats
        self.results = [None] * len(tasks)
        self.rss = [0.0] * len(tasks)
        self.pool: list[Worker] = []
        self.retired: list[Worker] = []
        self.submitted = 0

    def run(self, workers: int, progress) -> list:
        """Every task, one in flight per worker; the workers are stopped however it ends."""
        n = len(self.tasks)
        self.stats["workers"] = min(workers, n)
        done, clean = 0, False
        try:
            for _ in range(min(workers, n)):
                self.pool.append(self._new_worker())
            for w in self.pool:
                self._send_next(w)
            while done < n:
                self._reap_retired()
                ready = self._ready()
                for slot, w in enumerate(list(self.pool)):
                    if w.task is None or not (w.conn in ready or w.process.sentinel in ready):
                        continue
                    index = self._collect(w)
                    done += 1
                    if progress:
                        progress(done, n, index, self.results[index])
                    self._refill(slot, w)
            clean = True
        finally:
            _shutdown(self.pool + self.retired, graceful=clean)
        self.stats["worker_rss_mb_by_task"] = self.rss
        self.stats["worker_rss_mb"] = max(self.rss)
        return self.results

    def _new_worker(self) -> Worker:
        worker = Worker(self.ctx, self.fn)
        self.stats["worker_starts"] += 1
        return worker

    def _send_next(self, w: Worker) -> None:
        w.send(self.submitted, self.tasks[self.submitted])
        self.submitted += 1

    def _reap_retired(self) -> None:
        """Wait for the retired workers that have exited (they finish between tasks)."""
        for w in [w for w in self.retired if not w.process.is_alive()]:
            _shutdown([w], graceful=True)
            self.retired.remove(w)

    def _ready(self) -> set:
        """The pipes and process sentinels of the busy workers that have something to say."""
        busy = [w for w in self.pool if w.task is not None]
        return set(wait_any([w.conn for w in busy] + [w.process.sentinel for w in busy]))

    def _collect(self, w: Worker) -> int:
        """Store ``w``'s result and return its task index; re-raise the task's exception, or
        ``WorkerDied`` if the worker ended without answering."""
        try:
            index, ok, value, rss_mb = w.conn.recv()
        except (EOFError, OSError):
            w.process.join(1.0)
            raise WorkerDied(f"worker process {w.process.pid} died (exit code "
                             f"{w.process.exitcode}) while running task {w.task}") from None
        if not ok:
            raise value
        self.results[index], self.rss[index] = value, rss_mb
        w.task = None
        w.done += 1
        return index

    def _refill(self, slot: int, w: Worker) -> None:
        """The next task to the worker in ``slot``, a fresh worker if it has done its share."""
        if self.submitted >= len(self.tasks):
            return
        if self.max_tasks and w.done >= self.max_tasks:
            w.stop()
            self.retired.append(w)
            w = self.pool[slot] = self._new_worker()
        self._send_next(w)


def _shutdown(workers, graceful: bool) -> None:
    """Stop every worker and wait for it: asked politely after a normal end, terminated
    otherwise (exception, Ctrl-C); SIGKILL for any still alive after 1 s."""
    for w in workers:
        w.stop() if graceful else w.kill()
    for w in workers:
        w.process.join(1.0 if graceful else 0.5)
        if w.process.is_alive():
            w.process.terminate()
            w.process.join(1.0)
        if w.process.is_alive():
            w.process.kill()
            w.process.join(1.0)
        w.conn.close()
        try:
            w.process.close()
        except ValueError:
            pass
