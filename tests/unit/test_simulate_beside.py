"""run_outputs.simulate_beside: the simulation in a forked process while this one prepares
the figures; its result, its exceptions and its death reach the caller."""

import multiprocessing
import os
import types

import pytest

from ptint_drake.report import run_outputs
from ptint_drake.scenario import ScenarioError

pytestmark = pytest.mark.skipif("fork" not in multiprocessing.get_all_start_methods(),
                                reason="no fork on this platform")


@pytest.fixture(autouse=True)
def _forkable(monkeypatch):
    """Fork whatever an earlier test in this process left behind (a Meshcat, a thread makes
    ``can_fork`` say no): the fake simulations below touch none of it."""
    monkeypatch.setattr(run_outputs, "can_fork", lambda: True)


def _fake(behaviour):
    parent = os.getpid()

    def simulate(scenario, progress=None, warn=None):
        if behaviour == "raise":
            raise ScenarioError("interceptions[0].tf: unreachable")
        if behaviour == "die":
            if os.getpid() == parent:  # never end the test process itself
                raise AssertionError("the simulation ran in the test's own process")
            os._exit(3)
        return types.SimpleNamespace(metrics={"pid": os.getpid(), "scenario": scenario},
                                     series={"t": [0.0, 0.1]})
    return simulate


def test_the_simulation_runs_in_another_process_while_prepare_runs_here(monkeypatch):
    monkeypatch.setattr(run_outputs, "simulate", _fake("ok"))
    prepared = []
    metrics, series = run_outputs.simulate_beside("s", lambda: prepared.append(os.getpid()))
    assert prepared == [os.getpid()] and metrics["pid"] != os.getpid()
    assert metrics["scenario"] == "s" and series == {"t": [0.0, 0.1]}


def test_without_prepare_it_runs_here(monkeypatch):
    monkeypatch.setattr(run_outputs, "simulate", _fake("ok"))
    assert run_outputs.simulate_beside("s")[0]["pid"] == os.getpid()


def test_its_exception_is_raised_here(monkeypatch):
    monkeypatch.setattr(run_outputs, "simulate", _fake("raise"))
    with pytest.raises(ScenarioError, match=r"interceptions\[0\]\.tf"):
        run_outputs.simulate_beside("s", lambda: None)


def test_its_death_is_an_error_here(monkeypatch):
    monkeypatch.setattr(run_outputs, "simulate", _fake("die"))
    with pytest.raises(RuntimeError, match="exit code 3"):
        run_outputs.simulate_beside("s", lambda: None)
