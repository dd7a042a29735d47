"""Shared helpers: scenario runs cached per session (a run is deterministic).

``tests/unit`` holds the fast tests (no whole scenario is simulated: run them every few minutes,
``pytest tests/unit``); ``tests/e2e`` the end-to-end runs, marked ``e2e`` here (``-m "not e2e"``
deselects them).  Helper modules shared by both (``arms.py``, ``heavy_arm.py``, this file) sit in
``tests/``, which pytest puts on ``sys.path`` with this file."""

from __future__ import annotations

import functools
import subprocess

import pytest

from ptint_drake.scenario import load_scenario, parse_with_overrides, scenario_text
from ptint_drake.simulation import simulate

CURVES = ["curve_b025_tf15", "curve_b050_tf15", "curve_b075_tf15", "curve_b075_tf12",
          "curve_b075_tf19"]


@functools.lru_cache(maxsize=None)
def run_cached(name: str, overrides: str = ""):
    """simulate() of a bundled scenario, with an optional YAML override mapping."""
    if overrides:
        _, text = scenario_text(name)
        scenario = parse_with_overrides(text, overrides, name)
    else:
        scenario = load_scenario(name)
    return simulate(scenario)


def assert_prescribed_time(metrics: dict, label: str = "") -> None:
    """SPEC section 6 on every segment of a run's metrics."""
    for i, seg in enumerate(metrics["segments"]):
        where = f"{label} segment {i}"
        assert seg["e_tf_norm"] <= 1e-3, f"{where}: |e(tf)| = {seg['e_tf_norm']} m > 1 mm"
        if seg["e0_norm"] >= 1e-2:
            assert seg["e_half_norm"] >= 0.25 * seg["e0_norm"], (
                f"{where}: arrived early, |e(tf/2)| = {seg['e_half_norm']} < |e0|/4 = "
                f"{0.25 * seg['e0_norm']}")
        assert seg["e_hold_max_norm"] <= 3e-3, f"{where}: hold max {seg['e_hold_max_norm']} m > 3 mm"


@pytest.fixture
def run():
    return run_cached


@pytest.fixture
def ptint_here(capfd):
    """``ptint ARGS`` run in this process (``cli.main``), its result as a CompletedProcess.

    For bad-input checks (exit 2, one line, nothing written): the same code path as the
    command without paying a pydrake import per case.  stdout and stderr are captured at the
    file-descriptor level, so Drake's own C++ logging would show up too; an exception that
    escapes ``main`` fails the test (the subprocess would print a traceback).  Each command
    family keeps at least one real subprocess test for the process-level behaviour."""
    from ptint_drake import cli  # noqa: PLC0415

    def ptint(*args, **_ignored):
        capfd.readouterr()  # drop what the test printed before
        try:
            code = cli.main([str(a) for a in args])
        except SystemExit as exc:  # argparse: --help (0) and its usage errors (2)
            code = exc.code if isinstance(exc.code, int) else int(exc.code is not None)
        out, err = capfd.readouterr()
        return subprocess.CompletedProcess(["ptint", *args], code, out, err)
    return ptint


DYNAMICS = ("CalcMassMatrix", "CalcMassMatrixViaInverseDynamics", "CalcBiasTerm",
            "CalcGravityGeneralizedForces", "CalcInverseDynamics")


@pytest.fixture
def dynamics_calls(monkeypatch):
    """A list that records every Python call of a MultibodyPlant dynamics method (the
    controllers are Python systems: any use of the model would go through these)."""
    from pydrake.multibody.plant import MultibodyPlant  # noqa: PLC0415

    calls = []
    for name in DYNAMICS:
        original = getattr(MultibodyPlant, name)

        def spy(self, *args, _name=name, _original=original, **kwargs):
            calls.append(_name)
            return _original(self, *args, **kwargs)
        monkeypatch.setattr(MultibodyPlant, name, spy)
    return calls


def sigint_default() -> None:
    """``preexec_fn`` for a child that a test interrupts: SIGINT back to its default action
    (a shell's background job inherits it ignored, and Python then never raises
    KeyboardInterrupt), so the child behaves as under a terminal's Ctrl-C."""
    import signal  # noqa: PLC0415

    signal.signal(signal.SIGINT, signal.SIG_DFL)


# tf = 0.2 s for a 0.3 m reach: more than the RV-M1's actuators can do (a miss, not a failure)
TOO_SHORT_TF = """duration: 1.0
robot: {model: rvm1, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0]}
interceptions:
  - start: 0.0
    tf: 0.2
    beta: 0.75
    target: {linear: {start: [0.30, -0.15, 0.15], velocity: [0.0, 0.1, 0.0]}}
"""


# The longest files first (pyproject.toml runs the files on two processes, a whole file to one,
# in this order: a long file started last would keep one process busy while the other idles),
# then the other end-to-end files, then tests/unit.  Measured with --durations; order only.
LONGEST_FIRST = ("test_notebooks.py", "test_visuals.py", "test_pick_place.py", "test_runner.py",
                 "test_plugin.py", "test_sweep.py", "test_tune.py", "test_filter_floor.py",
                 "test_benchmark.py", "test_robustness.py", "test_pose.py", "test_controllers.py",
                 "test_switching.py", "test_cli_hygiene.py")


def _run_order(item) -> tuple:
    name = item.path.name
    e2e = "e2e" in item.path.parts
    return (not e2e, LONGEST_FIRST.index(name) if e2e and name in LONGEST_FIRST else len(LONGEST_FIRST))


def pytest_collection_modifyitems(config, items):
    """Mark every test under tests/e2e as ``e2e``; order the files (a stable sort: a file's tests
    keep their order)."""
    for item in items:
        if "e2e" in item.path.parts:
            item.add_marker(pytest.mark.e2e)
    items.sort(key=_run_order)
