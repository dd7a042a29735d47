"""studies.runner: order, identical results on every backend, progress, recycling, errors, Ctrl-C."""

import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest
from conftest import sigint_default

from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text
from ptint_drake.studies.robust import robust_sample
from ptint_drake.studies.runner import WorkerDied, run_tasks

HERE = Path(__file__).parent
NAME, TEXT = scenario_text("curve_b075_tf15")


def _slow_square(i, delay):
    time.sleep(delay)
    return i * i, os.getpid()


def _boom(i):
    if i == 2:
        raise ValueError(f"task {i} is bad")
    return i


def _die(i):
    if i == 1:
        os._exit(3)
    return i


def _stage_and_wait(out_dir):
    """Stage a file in ``out_dir`` and wait there until stopped."""
    from ptint_drake.outputs.folder import staged_output  # noqa: PLC0415

    with staged_output(out_dir) as stage:
        (stage / "half.txt").write_text("half")
        time.sleep(60)
    return "finished"


def _stage_and_wait_in_c(out_dir):
    """Stage a file, then wait inside C code that calls back into Python (libc's qsort with a
    slow comparison, as numba's cache is called back from LLVM): an exception raised in a
    callback is printed and swallowed there."""
    import ctypes  # noqa: PLC0415

    from ptint_drake.outputs.folder import staged_output  # noqa: PLC0415

    compare = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.POINTER(ctypes.c_int), ctypes.POINTER(ctypes.c_int))

    def slow(a, b):
        time.sleep(0.01)
        return a[0] - b[0]

    values = (ctypes.c_int * 5000)(*range(5000, 0, -1))
    with staged_output(out_dir) as stage:
        (stage / "half.txt").write_text("half")
        ctypes.CDLL(None).qsort(values, len(values), ctypes.sizeof(ctypes.c_int), compare(slow))
    return "finished"


def _fail_once_staged(out_dir):
    """Raise as soon as the other task's staged folder exists."""
    deadline = time.time() + 20
    while not list(Path(out_dir).glob(".ptint-stage-*")) and time.time() < deadline:
        time.sleep(0.01)
    raise ValueError("the other task is staged")


def _stage_or_fail(kind, out_dir):
    if kind == "fail":
        return _fail_once_staged(out_dir)
    return _stage_and_wait(out_dir) if kind == "stage" else _stage_and_wait_in_c(out_dir)


def _comparable(row):
    return {k: v for k, v in row.items() if k not in ("realtime_factor", "cpu_s")}  # clock dependent


def _new_children(before):
    """Child processes of this process that were not there ``before`` (a set of pids): other
    tests may leave helpers of their own (e.g. Dask's resource tracker) that are not ours, and
    the multiprocessing forkserver and its resource tracker (started once per process, when this
    process runs other threads: a Dask client, pytest-xdist's I/O thread) are not workers."""
    from multiprocessing import forkserver, resource_tracker  # noqa: PLC0415

    server = getattr(getattr(forkserver, "_forkserver", None), "_forkserver_pid", None)
    tracker = getattr(getattr(resource_tracker, "_resource_tracker", None), "_pid", None)
    return set(_children(os.getpid())) - before - {server, tracker}


def _children(pid):
    """Pids whose parent is ``pid``."""
    kids = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                kids.append(int(entry.name))
    return kids


def test_results_in_task_order_and_progress_sees_every_result():
    # later tasks finish first: the results still come back in task order
    tasks = [(i, 0.02 * (6 - i)) for i in range(6)]
    before = set(_children(os.getpid()))
    seen = []
    stats = {}
    results = run_tasks(_slow_square, tasks, workers=2, stats=stats,
                        progress=lambda done, total, index, result: seen.append((done, total, index, result)))
    assert [r[0] for r in results] == [i * i for i in range(6)]
    assert [s[0] for s in seen] == list(range(1, 7)) and all(s[1] == 6 for s in seen)
    assert sorted(s[2] for s in seen) == list(range(6))
    assert all(results[index] == result for _, _, index, result in seen)
    assert len({pid for _, pid in results}) == 2 and os.getpid() not in {pid for _, pid in results}
    assert stats["workers"] == 2 and stats["worker_rss_mb"] > 0
    assert not _new_children(before)  # every worker was waited for


def test_workers_are_recycled():
    stats = {}
    before = set(_children(os.getpid()))
    results = run_tasks(_slow_square, [(i, 0.0) for i in range(5)], workers=1, max_tasks_per_child=2,
                        stats=stats)
    pids = [pid for _, pid in results]
    assert pids[0] == pids[1] != pids[2] == pids[3] != pids[4]
    assert stats["worker_starts"] == 3
    assert not _new_children(before)


def test_a_task_error_is_raised_in_the_caller_and_no_worker_is_left():
    before = set(_children(os.getpid()))
    with pytest.raises(ValueError, match="task 2 is bad"):
        run_tasks(_boom, [(i,) for i in range(6)], workers=2)
    with pytest.raises(WorkerDied, match="exit code 3"):
        run_tasks(_die, [(i,) for i in range(4)], workers=2)
    assert not _new_children(before)


def test_a_stopped_worker_removes_its_half_written_folder(tmp_path):
    # the parent stops the other worker (SIGTERM) on the error: its staged folder unwinds
    before = set(_children(os.getpid()))
    start = time.time()
    with pytest.raises(ValueError, match="the other task is staged"):
        run_tasks(_stage_or_fail, [("stage", str(tmp_path)), ("fail", str(tmp_path))], workers=2)
    assert time.time() - start < 10
    assert list(tmp_path.iterdir()) == []  # no .ptint-stage-*, no half.txt
    assert not _new_children(before)


def test_a_worker_stopped_inside_a_c_callback_removes_its_folder_quietly(tmp_path, capfd):
    """Stopped while C code calls back into Python: nothing printed (no 'Exception ignored'
    traceback), no staged folder left, well before the parent's SIGKILL."""
    before = set(_children(os.getpid()))
    start = time.time()
    with pytest.raises(ValueError, match="the other task is staged"):
        run_tasks(_stage_or_fail, [("stage_in_c", str(tmp_path)), ("fail", str(tmp_path))], workers=2)
    assert time.time() - start < 10
    assert list(tmp_path.iterdir()) == []
    assert "Traceback" not in capfd.readouterr().err
    assert not _new_children(before)


@pytest.mark.slow
def test_robust_samples_identical_on_1_and_2_workers_and_on_dask():
    distributed = pytest.importorskip("distributed", reason="install the [cluster] extra")
    tasks = [(TEXT, NAME, 40 + i) for i in range(3)]
    one = run_tasks(robust_sample, tasks, workers=1)
    two = run_tasks(robust_sample, tasks, workers=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        seen = []
        on_dask = run_tasks(robust_sample, tasks, dask=cluster.scheduler_address,
                            progress=lambda done, total, index, result: seen.append(index))
    assert [r["seed"] for r in one] == [40, 41, 42]
    assert all(r["ok"] for r in one)
    assert [_comparable(r) for r in two] == [_comparable(r) for r in one]
    assert [_comparable(r) for r in on_dask] == [_comparable(r) for r in one]
    assert sorted(seen) == [0, 1, 2]


@pytest.mark.slow
def test_cli_dask_bad_address_is_one_line_exit_2(tmp_path):
    done = subprocess.run([sys.executable, "-m", "ptint_drake", "sweep", "curve_b075_tf15",
                           "--beta", "0.5", "--tf", "1.5", "--dask", "tcp://127.0.0.1:9",
                           "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, timeout=120, cwd=HERE)
    assert done.returncode == 2, done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("ptint: error: --dask") and "127.0.0.1:9" in lines[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_cli_ctrl_c_stops_robust_within_5_s(tmp_path):
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "ptint_drake.cli", "robust", "curve_b075_tf15",
                             "--samples", "300", "--workers", "2", "--out", str(out)],
                            cwd=HERE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True,  # its own process group, like a shell job
                            preexec_fn=sigint_default)
    try:
        deadline = time.time() + 60
        while time.time() < deadline and len(_children(proc.pid)) < 2:
            time.sleep(0.1)
        assert len(_children(proc.pid)) >= 2, "the workers did not start"
        time.sleep(2.0)  # in the middle of simulations
        t0 = time.time()
        os.killpg(proc.pid, signal.SIGINT)  # what the terminal does on Ctrl-C
        _, err = proc.communicate(timeout=10)
        elapsed = time.time() - t0
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    assert proc.returncode == 130, err
    assert elapsed < 5.0, elapsed
    assert "Traceback" not in err and "interrupted" in err
    time.sleep(0.2)
    with pytest.raises(ProcessLookupError):  # nothing is left in its process group
        os.killpg(proc.pid, 0)
    assert not out.exists()


def test_why_workers_are_recycled_a_simulation_is_never_freed(monkeypatch):
    """Why ``max_tasks_per_child``: the diagram of a simulation is never freed, on both Drake
    ends (1.51.1 and 1.58.0).  A LeafSystem of this package that holds a Drake cache entry
    (``systems.task.cache.DeclareVectorCache``: the entry's ``Eval`` kept on the system, a ``calc``
    that captures the system; ``TargetSource``, the controller's blocks) is in a reference cycle
    through C++ that Python's garbage collector cannot see, and keeps its diagram alive.  Drake
    1.51.1 keeps every Python LeafSystem alive; Drake 1.58.0 frees one without a cache entry
    (``ObjectRotations``), not these.  Measured (RSS after each of N = 120 runs in one process,
    5 runs of warm-up, gc.collect() after each; curve_b075_tf15): simulate() +1.04 MB per run on
    Drake 1.51.1 (Python 3.11) and +1.05 MB on 1.58.0 (Python 3.13); robust_sample() (camera
    and estimator, seeds 40 on) +1.54 and +1.55 MB per sample.  Should this fail on a newer
    Drake, measure again before dropping the recycling."""
    import gc
    import weakref
    from importlib.metadata import version

    from ptint_drake import simulation
    from ptint_drake.systems.task.orientation import ObjectRotations
    from ptint_drake.systems.task.targets import TargetSource
    from ptint_drake.worlds import runner
    from ptint_drake.worlds.registry import objects_of, schedule_of

    diagrams = []
    make = runner.make_simulator

    def make_and_watch(run):
        diagrams.append(weakref.ref(run.diagram))
        return make(run)

    monkeypatch.setattr(runner, "make_simulator", make_and_watch)
    scenario = parse_with_overrides(TEXT, (), NAME)
    assert simulation.simulate(scenario).ok
    source = weakref.ref(TargetSource(schedule_of(scenario), objects_of(scenario)))
    rotations = weakref.ref(ObjectRotations(objects_of(scenario)))
    gc.collect()
    assert len(diagrams) == 1 and diagrams[0]() is not None  # the run's diagram, plant and all
    assert source() is not None  # a leaf with a cache entry, alone
    if tuple(int(x) for x in version("drake").split(".")[:2]) >= (1, 58):
        assert rotations() is None  # the cache entry is what keeps it: a leaf without one is freed


def test_a_multi_threaded_caller_gets_forkserver_workers():
    """fork() copies only the calling thread: from a process with other threads (a Dask
    client, a notebook kernel) the workers come from a forkserver, with the same results."""
    import threading

    stop = threading.Event()
    helper = threading.Thread(target=stop.wait, daemon=True)
    helper.start()
    try:
        stats = {}
        results = run_tasks(_slow_square, [(i, 0.0) for i in range(4)], workers=2, stats=stats)
    finally:
        stop.set()
        helper.join()
    assert stats["start_method"] == "forkserver"
    assert [r[0] for r in results] == [0, 1, 4, 9]
    assert os.getpid() not in {pid for _, pid in results}


def _cube(i):
    return i ** 3, os.getpid()


def test_a_function_of_main_is_forked_even_beside_threads():
    """A notebook's or script's own function cannot be imported by a forkserver child, so it
    is forked (as before) whatever other threads run."""
    import threading

    fn = _cube
    fn.__module__ = "__main__"  # as if defined in a notebook cell: only a fork can run it
    stop = threading.Event()
    helper = threading.Thread(target=stop.wait, daemon=True)
    helper.start()
    try:
        stats = {}
        with warnings.catch_warnings():  # Python >= 3.12 warns about this very fork, rightly
            warnings.filterwarnings("ignore", "This process .* is multi-threaded", DeprecationWarning)
            results = run_tasks(fn, [(i,) for i in range(3)], workers=2, stats=stats)
    finally:
        stop.set()
        helper.join()
        fn.__module__ = __name__
    assert stats["start_method"] == "fork"
    assert [r[0] for r in results] == [0, 1, 8]
