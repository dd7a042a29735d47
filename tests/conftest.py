"""Shared helpers: scenario runs cached per session (a run is deterministic).

``tests/unit`` holds the fast tests (no whole scenario is simulated: run them every few minutes,
``pytest tests/unit``); ``tests/e2e`` the end-to-end runs, marked ``e2e`` here (``-m "not e2e"``
deselects them).  Helper modules shared by both (``arms.py``, ``heavy_arm.py``, this file) sit in
``tests/``, which pytest puts on ``sys.path`` with this file."""

from __future__ import annotations

import fcntl
import functools
import hashlib
import os
import pickle
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

import ptint_drake
from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import load_scenario, parse_with_overrides, scenario_text

# The folder this test process imports ``ptint_drake`` from: the source tree for an editable
# install, else the environment's site-packages (setup.sh's default, the README's test command).
# A subprocess that must run the same package gets it first on PYTHONPATH, and so finds numba's
# kernels where setup.sh compiled them; the tree itself, on a non-editable install, has none, and
# each process importing it compiles them again (measured on Drake 1.51.1, .ci/run's oldest end:
# 130 s of compiling in two processes).
IMPORTED_FROM = Path(ptint_drake.__file__).resolve().parents[1]

CURVES = ["curve_b025_tf15", "curve_b050_tf15", "curve_b075_tf15", "curve_b075_tf12",
          "curve_b075_tf19"]


# The pytest-xdist processes of one session share their runs through this folder (made by the
# controlling process, removed at its end): a run asked for in two files on two processes is
# simulated once, the second process waiting for the first's (a lock per run).
RUN_CACHE_ENV = "PTINT_TEST_RUN_CACHE"


def _simulate(name: str, overrides) -> object:
    if overrides:
        _, text = scenario_text(name)
        scenario = parse_with_overrides(text, overrides, name)
    else:
        scenario = load_scenario(name)
    return simulate(scenario)


def _drake_config(kind: type, fields: dict):
    return kind(**fields)


class _RunPickler(pickle.Pickler):
    """A run's scenario holds Drake's config structs (SimulatorConfig, MultibodyPlantConfig), which
    do not pickle: each is stored as its ``__fields__`` and built again from them."""

    def reducer_override(self, obj):
        fields = getattr(type(obj), "__fields__", None)
        if fields is not None and type(obj).__module__.startswith("pydrake"):
            return _drake_config, (type(obj), {f.name: getattr(obj, f.name) for f in fields})
        return NotImplemented


@functools.lru_cache(maxsize=None)
def run_cached(name: str, overrides: str = ""):
    """simulate() of a bundled scenario (or a scenario file), with an optional YAML override
    mapping (or a tuple of ``--set`` assignments); once per session across the xdist processes
    (a run is deterministic)."""
    folder = os.environ.get(RUN_CACHE_ENV)
    if not folder or not os.path.isdir(folder):
        return _simulate(name, overrides)
    key = hashlib.sha1(repr((name, overrides)).encode()).hexdigest()
    stored = Path(folder) / f"{key}.pickle"
    with open(Path(folder) / f"{key}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # the other process may be running it: wait for it
        if stored.exists():
            with open(stored, "rb") as f:
                return pickle.load(f)
        result = _simulate(name, overrides)
        partial = stored.with_suffix(".partial")
        with open(partial, "wb") as f:
            _RunPickler(f, protocol=pickle.HIGHEST_PROTOCOL).dump(result)
        partial.replace(stored)
        return result


def pytest_configure(config):
    """The controlling process of an xdist session makes the shared run folder."""
    if hasattr(config, "workerinput") or not getattr(config.option, "numprocesses", None):
        return
    config._ptint_run_cache = tempfile.mkdtemp(prefix="ptint-test-runs-")
    os.environ[RUN_CACHE_ENV] = config._ptint_run_cache


def pytest_unconfigure(config):
    folder = getattr(config, "_ptint_run_cache", None)
    if folder:
        shutil.rmtree(folder, ignore_errors=True)
        os.environ.pop(RUN_CACHE_ENV, None)


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


@pytest.fixture
def refused_run(tmp_path, ptint_here):
    """``ptint run SCENARIO --set OVERRIDE`` (no views) that must be refused: exit 2, one line on
    stderr, no traceback, no output folder; returns that line for the test's own checks."""
    def refused(scenario: str, override: str) -> str:
        out = tmp_path / "out"
        result = ptint_here("run", scenario, "--quiet", "--no-replay", "--no-figures", "--out", out,
                            "--set", override)
        lines = [line for line in result.stderr.splitlines() if line.strip()]
        assert result.returncode == 2, result.stderr
        assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
        assert not out.exists()
        return lines[0]
    return refused


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


# How the two pytest-xdist processes share the work.  A unit of work goes to one process whole:
# a file (its tests share module fixtures), except in SPLIT_FILES, whose tests go one by one (no
# module fixture; a run two of them need is shared through run_cached's folder) unless SHARED
# names a unit for several of them (they need the same run: one process runs it, the other would
# only wait for it).  The units go out longest first (a long one started last keeps one process
# busy while the other idles), by UNIT_SECONDS: one process, Drake 1.58, wall seconds measured with
# --durations on the shared 2-core machine (relative sizes); the others after them in collection
# order (tests/unit last).  pytest-xdist's own groups (``--dist loadgroup``, ``xdist_group``) do
# not work on pytest 9 (the group is written into a node id pytest no longer reads), hence the
# scheduler below.
SPLIT_FILES = {"test_notebooks.py", "test_lcm_two_processes.py", "test_tune.py", "test_pick_grasp.py",
               "test_pick_rgbd.py"}
SHARED = {  # file::test -> the unit's name
    "test_pick_rgbd.py::test_conveyor_pick_place_rgbd_places_a_randomly_placed_part_from_depth_images":
        "rgbd_stock_run",
    "test_pick_rgbd.py::test_e_true_is_against_the_simulated_part_and_e_estimate_against_the_estimate":
        "rgbd_stock_run",
}
# measured 2026-12-03 on one process (load 5-10 on the 2 cores: about 2.5 x the CPU seconds); the
# notebooks on two processes (the whole suite, 841 s at load 5-7; the three not listed < 12 s)
UNIT_SECONDS = {
    "test_visuals.py": 195,
    "test_tune.py::test_tune_finds_gains_for_a_heavy_six_joint_arm": 99,
    "test_runner.py": 85,
    "test_robustness.py": 63,
    **{f"test_notebooks.py::test_notebook_runs_and_reproduces_its_tables[{name}]": seconds
       for name, seconds in (("which_controller", 36), ("camera", 25), ("pick_and_place", 20),
                             ("hardware", 10), ("pose", 10), ("your_diagram", 10))},
    "test_sweep.py": 60,
    "test_tune.py::test_tune_on_the_paper_robot_says_how_it_compares": 57,
    "test_lcm_two_processes.py::test_pick_lockstep_places_like_one_process": 53,
    "test_lcm_two_processes.py::test_camera_pick_lockstep_places_like_one_process": 45,
    "test_world_plugin.py": 30,
    "test_filter_floor.py": 46,
    "test_plugin.py": 45,
    "test_benchmark.py": 43,
    "test_controllers.py": 41,
    "test_pick_robust.py": 37,
    "test_pick_place.py": 35,
    "test_cli_hygiene.py": 35,
    "test_compare.py": 34,
    "test_docs_build.py": 29,  # 2026-12-05, measured beside another engineer's runs
    "test_lcm_two_processes.py::test_lockstep_same_verdict_as_one_process": 24,
    "test_pick_two_belts.py": 22,
    "test_pick_rgbd.py::test_a_fit_forced_wrong_makes_the_pick_fail": 22,
    "test_lcm_two_processes.py::test_pick_replan_is_refused_in_one_line": 22,
    "test_pick_mirrored_six_joints.py": 19,
    "test_pick_rgbd.py::rgbd_stock_run": 17,
    "test_curves.py": 16,
    "test_tune.py::test_no_gain_can_save_a_too_short_tf": 15,
    "test_pick_rgbd.py::test_a_part_never_seen_is_not_grasped": 14,
    "test_lcm_two_processes.py::test_drive_killed_holds_the_arm": 14,
    "test_lcm_two_processes.py::test_realtime_run_completes": 13,
    "test_pick_grasp.py::test_closed_on_nothing_is_empty_and_the_retry_picks_the_part": 12,
    "test_lcm_two_processes.py::test_dropped_status_completes": 11,
    "test_lcm_two_processes.py::test_second_sender_detected": 11,
    "test_rgbd_frames.py": 11,
    "test_camera_loop.py": 11,
    "test_pick_collision.py": 10,
}


def work_unit(nodeid: str) -> str:
    """The unit of work of a test: its file's name, or ``file::test`` for a file split."""
    path, _, test = nodeid.partition("::")
    name = path.rsplit("/", 1)[-1]
    if name not in SPLIT_FILES:
        return name
    return f"{name}::{SHARED.get(f'{name}::' + test.split('[', 1)[0], test)}"


def pytest_xdist_make_scheduler(config, log):
    """``--dist loadfile`` (pyproject.toml) by ``work_unit`` instead of by file."""
    if config.getvalue("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadScopeScheduling  # noqa: PLC0415

    class UnitScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return work_unit(nodeid)

    return UnitScheduling(config, log)


def pytest_collection_modifyitems(config, items):
    """Mark every test under tests/e2e as ``e2e`` (a unit test marked ``slow`` is refused: the
    oldest Drake end runs every unit test); order the units of work longest first (a stable sort: a
    unit's tests keep their order)."""
    first = {}
    for k, item in enumerate(items):
        if "e2e" in item.path.parts:
            item.add_marker(pytest.mark.e2e)
        elif item.get_closest_marker("slow") is not None:
            raise pytest.UsageError(f"{item.nodeid}: only an e2e test may be marked slow")
        first.setdefault(work_unit(item.nodeid), k)

    def order(item) -> tuple:
        unit = work_unit(item.nodeid)
        return -UNIT_SECONDS.get(unit, 0), "e2e" not in item.path.parts, first[unit]
    items.sort(key=order)
