"""A user's own controller in the slot: ``controller: {type: "module:Class", params: {...}}``.

The example plugin of docs/own_controller.md (``examples/task_space_pd.py``) runs through ``ptint run`` and
``ptint compare`` from a folder of its own; broken plugins are one line and exit 2; a plugin
that raises while simulating fails its run, nothing else.
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import IMPORTED_FROM
from plugin_case import EXAMPLE, SCENARIO, TYPE

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import ScenarioError, parse_scenario

BROKEN = '''
import numpy as np
from pydrake.systems.framework import LeafSystem


class NoTarget(LeafSystem):
    def __init__(self, plant, end_effector, params):
        super().__init__()
        self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(), lambda c, o: o.SetZero())


class WrongSize(LeafSystem):
    def __init__(self, plant, end_effector, params):
        super().__init__()
        self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorInputPort("target", 9)
        self.DeclareVectorOutputPort("actuation", 7, lambda c, o: o.SetZero())


class Raises(LeafSystem):
    """Zero torque until t = 0.3 s, then a ZeroDivisionError; reads its segment port."""

    def __init__(self, plant, end_effector, params):
        super().__init__()
        self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorInputPort("target", 9)
        self.segment = self.DeclareVectorInputPort("segment", 3)
        self.seen = []
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(), self._calc)

    def _calc(self, context, output):
        self.seen.append((context.get_time(), *self.segment.Eval(context)))
        if context.get_time() > 0.3:
            raise ZeroDivisionError("my bug")
        output.SetZero()
'''


@pytest.fixture
def user_folder(tmp_path: Path) -> Path:
    """A user's folder: the example plugin, a broken one, and a scenario file beside them."""
    shutil.copy(EXAMPLE, tmp_path / EXAMPLE.name)
    (tmp_path / "broken_plugins.py").write_text(BROKEN)
    (tmp_path / "pd_scenario.yaml").write_text(SCENARIO % TYPE)
    return tmp_path


def ptint(*args, cwd) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"} | {
        "PYTHONPATH": str(IMPORTED_FROM)}  # (the package this process runs: conftest)
    return subprocess.run([sys.executable, "-m", "ptint_drake", *args], capture_output=True, text=True,
                          cwd=cwd, env=env, timeout=600)


def test_the_example_plugin_runs_from_its_scenario_folder_and_is_measured_like_any_controller(
        user_folder, tmp_path_factory):
    elsewhere = tmp_path_factory.mktemp("elsewhere")  # not the plugin's folder: found beside the scenario
    out = elsewhere / "run"
    done = ptint("run", str(user_folder / "pd_scenario.yaml"), "--out", str(out), "--no-replay",
                 "--no-figures", cwd=elsewhere)
    assert done.returncode in (0, 1), done.stderr
    m = json.loads((out / "metrics.json").read_text())
    assert m["controller"]["type"] == TYPE and m["sim"]["controller"] == TYPE
    seg = m["segments"][0]
    # it chased the target: the PD's error at tf is a small fraction of where it started
    assert seg["e_tf_norm"] < 0.2 * seg["e0_norm"], seg
    assert m["status"] in ("ok", "missed")


def test_compare_runs_the_plugin_beside_ptsmc_named_by_its_type_string(user_folder):
    out = user_folder / "cmp"
    done = ptint("compare", "pd_scenario.yaml", "--controllers", f"ptsmc,{TYPE}", "--variants", "nominal",
                 "--workers", "2", "--out", str(out), cwd=user_folder)
    assert done.returncode == 0, done.stderr
    rows = json.loads((out / "compare.json").read_text())["rows"]
    assert [r["controller"] for r in rows] == ["ptsmc", TYPE]
    ptsmc, mine = rows
    assert ptsmc["ok"] and ptsmc["segments"][0]["e_tf_norm"] < 1e-3
    assert mine["status"] in ("ok", "missed") and mine["segments"][0]["e_tf_norm"] is not None
    # both started from the same pose against the same target
    assert mine["segments"][0]["e0_norm"] == pytest.approx(ptsmc["segments"][0]["e0_norm"], rel=1e-9)


@pytest.mark.parametrize("type_, message", [
    ("no_such_module:X", r"controller\.type: cannot import 'no_such_module' for 'no_such_module:X'"),
    ("broken_plugins:Missing", r"controller\.type: 'broken_plugins' has no class 'Missing'"),
    ("broken_plugins:NoTarget", r"controller broken_plugins:NoTarget: needs an input port 'target'"),
    ("broken_plugins:WrongSize", r"controller broken_plugins:WrongSize: output port 'actuation' has 7 "
                                 r"values, needs 3"),
])
def test_a_broken_plugin_is_one_line_exit_2_and_writes_nothing(user_folder, type_, message, ptint_here,
                                                              monkeypatch):
    """``run`` and ``compare`` in this process (the tests above run the plugin's commands as real
    ones); the module search is the loaded scenario's folder and the current directory, so no
    state of this process carries over between the two."""
    import re  # noqa: PLC0415

    (user_folder / "bad.yaml").write_text(SCENARIO % type_)
    out = user_folder / "out_bad"
    monkeypatch.chdir(user_folder)
    done = ptint_here("run", "bad.yaml", "--out", str(out))
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and re.search(message, lines[0]), done.stderr
    assert not out.exists()
    compare = ptint_here("compare", "curve_b075_tf15", "--controllers", f"ptsmc,{type_}", "--out", str(out))
    assert compare.returncode == 2 and len(compare.stderr.strip().splitlines()) == 1, compare.stderr


def test_a_plugin_that_raises_fails_its_run_with_one_line_and_saw_its_segment(user_folder, monkeypatch):
    monkeypatch.chdir(user_folder)
    scenario = parse_scenario(SCENARIO % "broken_plugins:Raises")
    result = simulate(scenario, check=False)
    assert result.metrics["status"] == "failed"
    message = result.metrics["failure"]["message"]
    assert "broken_plugins:Raises" in message and "ZeroDivisionError: my bug" in message
    assert "\n" not in message
    system = sys.modules["broken_plugins"]
    del system  # the module stays importable; the instance lives in the run's diagram


def test_tune_takes_a_plugin_parameter_with_its_range(user_folder, ptint_here, monkeypatch):
    from ptint_drake.studies import tune  # noqa: PLC0415

    scenario = parse_scenario((user_folder / "pd_scenario.yaml").read_text())
    tuned = tune._set_gain(scenario, "params.Kp", 3000.0)
    assert tuned.controller.params == {"Kp": 3000.0, "Kd": 150.0}
    assert scenario.controller.params["Kp"] == 2000.0
    assert tune.gain_value(tuned, "params.Kp") == 3000.0
    with pytest.raises(ScenarioError, match=r"^--range: params\.Kp needs --range LO,HI"):
        tune.check_gain("params.Kp", ())
    monkeypatch.chdir(user_folder)
    done = ptint_here("tune", "pd_scenario.yaml", "--gain", "params.Kp", "--out", str(user_folder / "t"))
    assert done.returncode == 2, done.stderr
    assert done.stderr.startswith("ptint: error: --range: params.Kp needs"), done.stderr
    assert not (user_folder / "t").exists()


@pytest.mark.slow
def test_dask_workers_find_the_plugin_beside_its_scenario_file(user_folder):
    """Dask worker processes start elsewhere: the runner hands them the scenario's folder."""
    distributed = pytest.importorskip("distributed", reason="install the [cluster] extra")
    from ptint_drake.simulation.scenario import LoadedScenario  # noqa: PLC0415
    from ptint_drake.studies.compare import run_compare  # noqa: PLC0415

    assert Path.cwd() != user_folder
    loaded = LoadedScenario.load(str(user_folder / "pd_scenario.yaml"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        result = run_compare(loaded, [TYPE], ["nominal"], dask=cluster.scheduler_address)
    row = result["rows"][0]
    assert row["controller"] == TYPE and row["status"] in ("ok", "missed"), row.get("reasons")


def test_the_plugin_and_ptsmc_on_an_arm_the_package_has_never_seen(user_folder, monkeypatch):
    from arms import OFFSET_ARM  # noqa: PLC0415

    from ptint_drake.simulation.scenario import LoadedScenario  # noqa: PLC0415
    from ptint_drake.studies.compare import run_compare  # noqa: PLC0415

    (user_folder / "offset_arm.urdf").write_text(OFFSET_ARM)
    (user_folder / "arm.yaml").write_text(f"""duration: 2.0
robot: {{model: {user_folder / "offset_arm.urdf"}, end_effector: hand, initial_q_deg: [17.2, 28.6, 68.8]}}
controller: {{type: "{TYPE}", params: {{Kp: 3000.0, Kd: 200.0}}}}
interceptions:
  - start: 0.0
    tf: 1.0
    beta: 0.75
    target: {{linear: {{start: [0.45, 0.12, 0.75], velocity: [0, 0.02, 0]}}}}
""")
    monkeypatch.chdir(user_folder.parent)  # found beside the scenario file, not in the cwd
    loaded = LoadedScenario.load(str(user_folder / "arm.yaml"))
    result = run_compare(loaded, ["ptsmc", TYPE], ["nominal"], workers=1)
    rows = {r["controller"]: r for r in result["rows"]}
    assert set(rows) == {"ptsmc", TYPE}
    assert rows["ptsmc"]["ok"], rows["ptsmc"]["reasons"]
    mine = rows[TYPE]["segments"][0]
    assert rows[TYPE]["status"] in ("ok", "missed") and mine["e_tf_norm"] < mine["e0_norm"]
