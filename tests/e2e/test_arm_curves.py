"""Issue 45: the bundled iiwa14, Panda and UR5e run the paper's curve like the RV-M1 does."""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import assert_prescribed_time
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.robot.rvm1 import model_path

ARMS = ("iiwa14", "panda", "ur5e")


@pytest.mark.slow
@pytest.mark.parametrize("arm", ARMS)
def test_curve_meets_prescribed_time(tmp_path, arm):
    """``ptint run curve_ARM`` exits 0; |e(tf)| ≤ 1 mm, not before tf/2, hold ≤ 3 mm; with the
    null-space damping of the bundled file no joint leaves its range."""
    out = subprocess.run([sys.executable, "-m", "ptint_drake", "run", f"curve_{arm}", "--out", str(tmp_path),
                          "--no-replay", "--no-figures", "--quiet"], capture_output=True, text=True,
                         cwd=Path(__file__).parent, timeout=600)
    assert out.returncode == 0, out.stderr[-2000:]
    metrics = json.loads((tmp_path / "metrics.json").read_text())
    assert metrics["status"] == "ok"
    assert_prescribed_time(metrics, f"curve_{arm}")
    assert metrics["segments"][0]["e_tf_norm"] <= 1e-3
    q = np.load(tmp_path / "series.npz")["q"]
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path(arm)))
    plant.Finalize()
    q = q if q.shape[-1] == plant.num_positions() else q.T
    assert np.all(q >= plant.GetPositionLowerLimits()) and np.all(q <= plant.GetPositionUpperLimits())


def test_unknown_model_is_one_line(tmp_path, ptint_here):
    out = ptint_here("run", "curve_iiwa14", "--set", "robot.model=iiwa15", "--out", str(tmp_path / "out"),
                     "--quiet")
    assert out.returncode == 2
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith("ptint: error: --set: robot.model: 'iiwa15'") and "iiwa14" in lines[0]
    assert not (tmp_path / "out" / "metrics.json").exists()


def test_list_names_each_arm_curve(ptint_here):
    out = ptint_here("list")
    names = [line.split()[0] for line in out.stdout.splitlines() if line.strip()]
    assert {f"curve_{arm}" for arm in ARMS} <= set(names)
