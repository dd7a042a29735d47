"""Command-line hygiene: --help, closed pipes, --out, --set paths, progress, file modes."""

import io
import json
import os
import re
import shlex
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from ptint_drake import cli
from ptint_drake.cli import runs as cli_runs
from ptint_drake.config.yaml_io import override_text
from ptint_drake.outputs.folder import staged_output, write_json_atomic
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, scenario_text

TESTS = Path(__file__).parent


def ptint(*args):
    return subprocess.run([sys.executable, "-m", "ptint_drake", *args], check=False, capture_output=True,
                          text=True, cwd=TESTS, timeout=600)


def _one_error_line(out):
    assert "Traceback" not in out.stderr, out.stderr
    lines = [line for line in out.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, out.stderr
    assert lines[0].startswith("ptint: error: "), lines[0]
    return lines[0]


def _subcommands():
    return sorted(cli.make_parser()._subparsers._group_actions[0].choices)


@pytest.mark.parametrize("command", [None] + _subcommands())
def test_help_of_every_subcommand_exits_0(command, ptint_here):
    """In this process; ``ptint --help`` also as a real command (the next test)."""
    out = ptint_here(*([command] if command else []), "--help")
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("usage: ptint"), out.stdout[:200]
    assert "SPEC" not in out.stdout  # users get the docs and the paper, not SPEC


def test_help_as_a_command_exits_0():
    out = ptint("--help")
    assert out.returncode == 0 and out.stdout.startswith("usage: ptint"), out.stderr


def test_every_subcommand_is_tested():
    assert {"list", "run", "paper", "diagram", "sweep", "robust", "bench"} <= set(_subcommands())


@pytest.mark.parametrize("reader", ["head -1", "true"])
def test_closed_pipe_ends_quietly(reader):
    """`ptint list | head -1` through a real shell pipe: no traceback, no 'Exception ignored'."""
    cmd = f"{shlex.quote(sys.executable)} -m ptint_drake list | {reader}"
    out = subprocess.run(["bash", "-c", cmd], check=False, capture_output=True, text=True, cwd=TESTS,
                         timeout=120)
    assert out.stderr == "", out.stderr
    if reader == "head -1":
        assert len(out.stdout.splitlines()) == 1


@pytest.mark.parametrize("command", [
    ["run", "curve_b075_tf15", "--no-replay", "--no-figures"],
    ["diagram", "curve_b075_tf15"],
    ["sweep", "curve_b075_tf15", "--beta", "0.5", "--tf", "1.5", "--workers", "1"],
    ["robust", "curve_b075_tf15", "--samples", "1", "--workers", "1"],
    ["paper"],
])
def test_out_naming_a_file_is_one_line_exit_2(tmp_path, command, ptint_here):
    afile = tmp_path / "afile"
    afile.write_text("keep me\n")
    expected = {afile: f"ptint: error: --out: {afile} is a file",
                afile / "sub": f"ptint: error: --out: {afile} (in {afile / 'sub'}) is a file"}
    for out_arg, message in expected.items():
        out = ptint_here(*command, "--out", str(out_arg), "--quiet")
        assert out.returncode == 2, out.stderr
        assert _one_error_line(out) == message
    assert afile.read_text() == "keep me\n"


# --------------------------------------------------------------------------- --set paths

BASE = scenario_text("assembly")[1]


def test_override_text_reaches_list_items():
    import yaml

    text = override_text(BASE, ["interceptions[0].tf=1.2",
                                    "interceptions[1].target.linear.velocity=[0,0.2,0]",
                                    "controller.K=40", "measurement.noise_std=1e-5"])
    tree = yaml.safe_load(text)
    assert tree["interceptions"][0]["tf"] == 1.2
    assert tree["interceptions"][1]["target"]["linear"]["velocity"] == [0, 0.2, 0]
    assert tree["interceptions"][2] == yaml.safe_load(BASE)["interceptions"][2]
    assert tree["controller"]["K"] == 40
    assert tree["measurement"] == {"noise_std": 1e-5}
    scenario = LoadedScenario.load("assembly", ["interceptions[1].target.linear.velocity=[0,0.2,0]",
                                                "interceptions[0].tf=0.6"]).scenario
    assert scenario.interceptions[0].tf == 0.6 and scenario.interceptions[1].tf == 1.4
    assert list(scenario.interceptions[1].target.linear.velocity) == [0.0, 0.2, 0.0]
    assert scenario.name == "assembly"


BAD_SETS = {
    "interceptions[3].tf=1": "interceptions[3].tf",       # index out of range
    "controller.K[0]=1": "controller.K[0]",               # indexing a number
    "interceptions.tf=1": "interceptions.tf",             # a list, not a mapping
    "interceptions[0].target.foo=1": "interceptions[0].target.foo",  # unknown field
    "interceptions[0.tf=1": "interceptions[0.tf",         # not a path
    "duration": "duration",                               # no value
}


@pytest.mark.parametrize("pair", sorted(BAD_SETS))
def test_bad_set_path_names_it(pair):
    with pytest.raises(ScenarioError) as err:
        LoadedScenario.load("assembly", [pair])
    assert BAD_SETS[pair] in str(err.value) and "\n" not in str(err.value)


@pytest.mark.parametrize("pair", ["interceptions[1].tf=1.2", "controller.K[0]=1"])
def test_bad_set_path_on_the_command_line(tmp_path, pair, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--set", pair, "--out", str(tmp_path / "o"), "--quiet")
    assert out.returncode == 2
    assert BAD_SETS.get(pair, pair.split("=")[0]) in _one_error_line(out)
    assert not (tmp_path / "o" / "metrics.json").exists()


def test_set_on_a_list_item_changes_the_run(tmp_path, ptint_here):
    out = ptint_here("run", "curve_b075_tf15", "--set", "interceptions[0].tf=1.2", "--no-replay",
                "--no-figures", "--quiet", "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    m = json.loads((tmp_path / "metrics.json").read_text())
    assert m["segments"][0]["tf"] == 1.2
    assert m["scenario_config"]["interceptions"][0]["tf"] == 1.2
    assert m["segments"][0]["e_tf_norm"] < 1e-3


# --------------------------------------------------------------------------- progress


def test_progress_prints_a_line_per_tenth_when_not_a_tty(monkeypatch):
    err = io.StringIO()  # not a terminal
    monkeypatch.setattr(sys, "stderr", err)
    report = cli_runs.progress("demo")
    for k in range(61):
        report(0.05 * k, 3.0, steps=10 * k)
    report(3.0, 3.0)  # the final call of simulate; already reported
    lines = err.getvalue().splitlines()
    assert [int(re.search(r"(\d+) %", line).group(1)) for line in lines] == list(range(0, 101, 10))
    assert "steps" in lines[1] and lines[-1].startswith("demo: 100 %")
    report2 = cli_runs.progress("two-arg")
    report2(1.5, 3.0)  # the (t, duration) signature still works
    assert err.getvalue().splitlines()[-1] == "two-arg:  50 % (1.50/3.00 s simulated)"


def test_progress_lines_appear_on_a_non_tty_stderr(tmp_path, ptint_here):
    """``ptint run`` in this process, its stderr captured (not a terminal).  The watchdog
    reports at most every 0.2 s of wall time, so the run is long enough (40 s simulated, about
    a second) for lines between 0 % and 100 % on a fast machine too (12 s took 0.3 s and gave
    one)."""
    out = ptint_here("run", "curve_b075_tf15", "--set", "duration=40", "--no-replay", "--no-figures",
                "--out", str(tmp_path))
    assert out.returncode == 0, out.stderr
    lines = [line for line in out.stderr.splitlines() if re.search(r"\d+ % \(", line)]
    during = [line for line in lines if 0 < int(re.search(r"(\d+) %", line).group(1)) < 100]
    assert len(lines) >= 3 and during, out.stderr  # during the run, not only at the end
    assert lines[-1].startswith("curve_b075_tf15: 100 %")
    assert "\r" not in out.stderr


# --------------------------------------------------------------------------- file modes


def _modes(root: Path):
    return {p: stat.S_IMODE(p.stat().st_mode) for p in [root, *root.rglob("*")]}


def test_atomic_and_staged_files_follow_the_umask(tmp_path):
    old = os.umask(0o022)
    try:
        write_json_atomic(tmp_path / "a.json", {"x": 1})
        assert stat.S_IMODE((tmp_path / "a.json").stat().st_mode) == 0o644
        with staged_output(tmp_path / "out") as stage:
            assert stat.S_IMODE(stage.stat().st_mode) == 0o755
            (stage / "sub").mkdir()
            (stage / "sub" / "f.txt").write_text("x")
            write_json_atomic(stage / "metrics.json", {})
        os.umask(0o077)
        write_json_atomic(tmp_path / "b.json", {"x": 1})
        assert stat.S_IMODE((tmp_path / "b.json").stat().st_mode) == 0o600
    finally:
        os.umask(old)
    modes = _modes(tmp_path / "out")
    assert len(modes) == 5  # out, sub, sub/f.txt, metrics.json, the manifest
    for path, mode in modes.items():
        assert mode == (0o755 if path.is_dir() else 0o644), (path, oct(mode))


def test_run_and_robust_outputs_readable_under_umask_022(tmp_path, ptint_here):
    """Both commands in this process under umask 022 (the package reads the umask when it
    writes, and the figure workers it forks inherit it)."""
    run_dir, robust_dir = tmp_path / "run", tmp_path / "robust"
    old = os.umask(0o022)
    try:
        out = ptint_here("run", "curve_b075_tf15", "--no-replay", "--quiet", "--out", str(run_dir))
        assert out.returncode == 0, out.stderr
        out = ptint_here("robust", "curve_b075_tf15", "--samples", "1", "--workers", "1", "--quiet",
                         "--out", str(robust_dir))
        assert out.returncode == 0, out.stderr
    finally:
        os.umask(old)
    for root, must in ((run_dir, {"metrics.json", "series.npz", "axes.png", ".ptint-manifest.json"}),
                       (robust_dir, {"robust.json", "samples.json", "worst.yaml", "robust.png"})):
        modes = _modes(root)
        assert must <= {p.name for p in modes}
        for path, mode in modes.items():
            assert mode == (0o755 if path.is_dir() else 0o644), (path, oct(mode))
