"""A world of the user's own (issue 43): ``tests/worlds/touch_world.py`` — the gripper's tool
touches a fixed point at the prescribed time — named in its scenario as ``world: {type:
"touch_world:TouchWorld"}``, runs through ``ptint run``, ``ptint robust`` and ``ptint hardware``
+ ``ptint drive`` with no edit to the package."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
from lcm_link.netns import require_netns, run_in_netns

pytestmark = pytest.mark.e2e

WORLDS = Path(__file__).resolve().parents[1] / "worlds"
TOUCH = str(WORLDS / "touch.yaml")
PAIR = Path(__file__).resolve().parents[1] / "lcm_link" / "pair.py"


def ptint(*args: str) -> list[str]:
    return [sys.executable, "-m", "ptint_drake.cli", *args]


def run(*args: str, cwd: Path):
    import subprocess  # noqa: PLC0415

    return subprocess.run(ptint(*args), capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.mark.both_ends
def test_run_touches_at_tf_and_not_before(tmp_path):
    """The plugin world's verdict is the segment criteria: within 1 mm at tf, not before tf/2
    (|e(tf/2)| ≥ |e0|/4; on the ideal surface |e0|/2), held within 3 mm after."""
    done = run("run", TOUCH, "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    metrics = json.loads((tmp_path / "out" / "metrics.json").read_text())
    seg = metrics["segments"][0]
    assert metrics["status"] == "ok" and seg["e_tf_norm"] < 1e-3 and seg["e_hold_max_norm"] < 3e-3
    assert 0.4 * seg["e0_norm"] < seg["e_half_norm"] < 0.6 * seg["e0_norm"], seg
    assert metrics["touch"]["miss_m"] == seg["e_tf_norm"] and "touch: ok" in done.stdout


def test_robust_draws_the_arm_and_judges_by_the_world(tmp_path):
    """``ptint robust`` on the plugin world: the arm's own deviations (the protocol's default),
    each sample judged by the world's verdict."""
    done = run("robust", TOUCH, "--samples", "3", "--workers", "1", "--out", str(tmp_path / "r"),
               cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    result = json.loads((tmp_path / "r" / "robust.json").read_text())
    assert result["samples"] == 3 and result["success_rate"] == 1.0, result["failures"]
    rows = json.loads((tmp_path / "r" / "samples.json").read_text())
    assert len({r["params"]["mass_scale"] for r in rows}) == 3 and "noise_std" not in rows[0]["params"]


def test_sweep_is_refused_in_one_line(tmp_path):
    """A β × tf grid is a world's own: the protocol's default refuses it, row by row, by name."""
    done = run("sweep", TOUCH, "--beta", "0.5", "--tf", "1.0", "--workers", "1", "--out", str(tmp_path / "s"),
               cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert "the touch world has no β × tf grid to sweep" in (tmp_path / "s" / "sweep.csv").read_text()


@pytest.mark.slow
def test_hardware_and_drive_lockstep_match_one_process(tmp_path):
    """``ptint hardware`` + ``ptint drive`` on the plugin world in lockstep = ``ptint run`` with
    the same 1 ms control period and plant step: e(tf) within 1e-9 m."""
    require_netns()
    plan = [
        {"name": "hw", "argv": ptint("hardware", TOUCH, "--startup-timeout", "60", "--lockstep", "--quiet",
                                     "--out", str(tmp_path / "hw"))},
        {"name": "drive",
         "argv": ptint("drive", TOUCH, "--startup-timeout", "60", "--out", str(tmp_path / "dr"))},
    ]
    done = run_in_netns([sys.executable, str(PAIR), json.dumps(plan)], timeout=200, cwd=tmp_path)
    out = json.loads(done.stdout)
    assert out["hw"]["rc"] == 0 and out["drive"]["rc"] == 0, out
    hw = json.loads((tmp_path / "hw" / "metrics.json").read_text())
    one = run("run", TOUCH, "--set", "controller.control_period=0.001", "--set", "multibody.time_step=0.001",
              "--no-replay", "--no-figures", "--out", str(tmp_path / "one"), cwd=tmp_path)
    assert one.returncode == 0, one.stderr
    ref = json.loads((tmp_path / "one" / "metrics.json").read_text())
    assert hw["status"] == ref["status"] == "ok"
    assert abs(hw["segments"][0]["e_tf_norm"] - ref["segments"][0]["e_tf_norm"]) <= 1e-9
    assert hw["hardware"]["ticks"] == 1500 and hw["hardware"]["fault"] is None


@pytest.mark.parametrize("text, words", [
    ("touch_world:Nope", "world.type: 'touch_world' has no class 'Nope'"),
    ("no_such_module:TouchWorld", "world.type: cannot import 'no_such_module'"),
    ("touch_world", "world.type: expected 'module:Class'"),
    ("touch_world:TouchRun", "is not a ptint_drake.worlds.base.World subclass"),
])
@pytest.mark.slow
def test_a_bad_world_type_is_one_line(tmp_path, text, words):
    scenario = tmp_path / "bad.yaml"
    scenario.write_text((WORLDS / "touch.yaml").read_text().replace("touch_world:TouchWorld", text))
    (tmp_path / "touch_world.py").write_text((WORLDS / "touch_world.py").read_text())
    done = run("run", str(scenario), "--out", str(tmp_path / "out"), cwd=tmp_path)
    assert done.returncode == 2 and words in done.stderr and "Traceback" not in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()
