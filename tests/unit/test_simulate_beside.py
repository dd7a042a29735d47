"""run_outputs.simulate_beside: the simulation in a forked process while this one prepares
the figures; its result, its exceptions and its death reach the caller.  The fork is only
taken where it is provably safe (``can_fork``: no Python thread but the caller's), so the
forking cases run in a fresh single-threaded Python, as the command line is, where Python's
"multi-threaded fork" DeprecationWarning is shown (it cannot be made an error: os.fork
swallows it) and must not appear; a pytest-xdist worker (its
execnet I/O thread) and a process with a thread of its own simulate in-process instead."""

import _thread
import json
import multiprocessing
import os
import subprocess
import sys
import threading
import types

import pytest

from ptint_drake.report import run_outputs

pytestmark = pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(),
                                reason="no fork on this platform")

# Run in a fresh interpreter: each case's outcome as one JSON line.
FORKED = r'''
import json, os, sys, types
from ptint_drake.report import run_outputs
from ptint_drake.simulation.scenario import ScenarioError

parent = os.getpid()

def fake(behaviour):
    def simulate(scenario, progress=None, warn=None):
        if behaviour == "raise":
            raise ScenarioError("interceptions[0].tf: unreachable")
        if behaviour == "die":
            if os.getpid() == parent:  # never end this process itself
                raise AssertionError("the simulation ran in the caller's own process")
            os._exit(3)
        return types.SimpleNamespace(metrics={"pid": os.getpid(), "scenario": scenario},
                                     series={"t": [0.0, 0.1]})
    return simulate

print(json.dumps({"case": "can_fork", "value": run_outputs.can_fork()}))
for behaviour in ("ok", "raise", "die"):
    run_outputs.simulate = fake(behaviour)
    prepared = []
    try:
        metrics, series = run_outputs.simulate_beside("s", lambda: prepared.append(os.getpid()))
        outcome = {"metrics": metrics, "series": series}
    except (ScenarioError, RuntimeError) as exc:
        outcome = {"error": type(exc).__name__, "message": str(exc)}
    print(json.dumps({"case": behaviour, "parent": parent, "prepared": prepared, **outcome}))
'''


@pytest.fixture(scope="module")
def forked():
    """The cases of ``FORKED``, by name, run in one fresh process."""
    out = subprocess.run([sys.executable, "-W", "always::DeprecationWarning", "-c", FORKED],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "multi-threaded" not in out.stderr, out.stderr
    return {case["case"]: case for case in map(json.loads, out.stdout.splitlines())}


def test_a_fresh_process_may_fork(forked):
    assert forked["can_fork"]["value"] is True


def test_the_simulation_runs_in_another_process_while_prepare_runs_here(forked):
    case = forked["ok"]
    assert case["prepared"] == [case["parent"]] and case["metrics"]["pid"] != case["parent"]
    assert case["metrics"]["scenario"] == "s" and case["series"] == {"t": [0.0, 0.1]}


def test_its_exception_is_raised_here(forked):
    case = forked["raise"]
    assert case["error"] == "ScenarioError" and case["message"].startswith("interceptions[0].tf")


def test_its_death_is_an_error_here(forked):
    case = forked["die"]
    assert case["error"] == "RuntimeError" and "exit code 3" in case["message"]


def _here(monkeypatch):
    """A fake simulation that records the process it ran in."""
    monkeypatch.setattr(run_outputs, "simulate", lambda scenario, progress=None, warn=None:
                        types.SimpleNamespace(metrics={"pid": os.getpid()}, series={}))


def test_without_prepare_it_runs_here(monkeypatch):
    _here(monkeypatch)
    assert run_outputs.simulate_beside("s")[0]["pid"] == os.getpid()


@pytest.mark.parametrize("start", ["threading", "_thread"])
def test_beside_another_python_thread_it_runs_here(monkeypatch, start):
    """A thread of ``threading`` or one started with ``_thread`` (as pytest-xdist's I/O thread
    is, unseen by ``threading.active_count``): no fork, the simulation runs in this process."""
    _here(monkeypatch)
    started, stop = threading.Event(), threading.Event()

    def wait():
        started.set()
        stop.wait()

    if start == "threading":
        threading.Thread(target=wait, daemon=True).start()
    else:
        _thread.start_new_thread(wait, ())
    started.wait()
    try:
        assert not run_outputs.can_fork()
        assert run_outputs.simulate_beside("s", lambda: None)[0]["pid"] == os.getpid()
    finally:
        stop.set()
