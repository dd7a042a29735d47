"""What a newcomer meets first (issue 47): ``ptint --version``, ``ptint list``'s summaries, the
opening and closing lines of ``ptint run``, and ``ptint paper``'s summary line and progress."""

import importlib.metadata
import re
from pathlib import Path

import pytest

from ptint_drake import cli
from ptint_drake.report import paper_report
from ptint_drake.simulation.scenario import bundled_scenarios, scenario_text


def test_version_names_the_package_and_drake(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["--version"])
    assert stop.value.code == 0
    out = capsys.readouterr().out
    assert out.startswith("ptint (ptint_drake) ")
    assert f"Drake {importlib.metadata.version('drake')}" in out
    assert f"ptint_drake) {importlib.metadata.version('ptint_drake')}," in out
    assert len(out.splitlines()) == 1


def test_list_shows_whole_summaries_without_issue_numbers(capsys):
    assert cli.main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[0] for line in lines] == bundled_scenarios()
    for line in lines:
        name, summary = line.split(maxsplit=1)
        assert summary.endswith("."), line  # a whole sentence, not one cut at the file's line end
        assert not re.search(r"(?i)\bissues? \d+", summary), line
        assert len(summary) <= 110, line
        # the file's first line is all of it: a blank comment line or the YAML follows it
        following = scenario_text(name)[1].splitlines()[1]
        assert following == "#" or not following.startswith("#"), (name, following)


def _run(tmp_path, capsys, *extra) -> list[str]:
    code = cli.main(["run", "curve_b075_tf12", "--set", "duration=1.3", "--out", str(tmp_path / "o"),
                     "--quiet", "--no-figures", "--no-replay", *extra])
    assert code == 0
    return capsys.readouterr().out.splitlines()


def test_run_opens_with_what_runs_and_ends_with_the_verdict(tmp_path, capsys):
    lines = _run(tmp_path, capsys)
    assert lines[0] == (f"running curve_b075_tf12: the interception world, 1.3 s simulated, controller "
                        f"ptsmc (its settings: --verbose); outputs in {tmp_path / 'o'}/")
    assert lines[-1] == "curve_b075_tf12: ok (every segment meets the criteria)"
    assert not any(line.startswith("ptsmc: K = ") for line in lines)
    verbose = _run(tmp_path, capsys, "--verbose")
    assert verbose[0] == lines[0] and verbose[-1] == lines[-1]
    assert verbose[1] == "ptsmc: K = 50, Λ = 5, k = 3, tanh law"


def _metrics(status="ok", reasons=()):
    return {"status": status, "reasons": list(reasons)}


def test_the_paper_summary_counts_the_scenarios_reproduced():
    names = list(paper_report.PAPER_SCENARIOS)
    index = Path("out/paper/index.html")
    every = paper_report.summary_line({n: _metrics() for n in names}, index)
    assert every == ("paper: 6/6 scenarios reproduced (every segment: |e(tf)| <= 1 mm, not early, "
                     "hold <= 3 mm; docs/results.md); open out/paper/index.html in a browser")
    some = {n: _metrics() for n in names} | {"assembly": _metrics("missed", ["segment 0: hold"]),
                                              "curve_b025_tf15": _metrics("failed")}
    line = paper_report.summary_line(some, index)
    assert line.startswith("paper: 4/6 scenarios reproduced (")
    assert "; not reproduced: curve_b025_tf15: failed, assembly: missed (segment 0: hold); " in line
    assert line.endswith("; open out/paper/index.html in a browser")


def test_ptint_paper_ends_with_the_summary_line(tmp_path, capsys, monkeypatch):
    """The command's last line is ``summary_line`` of what ``write_paper`` ran (faked here:
    tests/e2e/test_visuals.py runs the real one)."""
    index = tmp_path / "index.html"
    metrics = {n: _metrics() for n in paper_report.PAPER_SCENARIOS} | {"assembly": _metrics("missed", ["x"])}
    monkeypatch.setattr(paper_report, "write_paper", lambda out, **kwargs: (index, metrics))
    assert cli.main(["paper", "--out", str(tmp_path), "--quiet"]) == 0
    last = capsys.readouterr().out.splitlines()[-1]
    assert last == paper_report.summary_line(metrics, index)
    assert last.startswith("paper: 5/6 scenarios reproduced") and last.endswith(f"{index} in a browser")


def test_every_kind_of_paper_job_reports_its_last_one(monkeypatch):
    """The jobs after the paper scenarios' runs (comparisons, holds, figures) report as they
    finish: at most one line per interval, and always the last job of each kind."""
    runs = ["assembly", "curve_b025_tf15"]
    tasks = ([("run", n) for n in runs] + [("camera", "c")] + [("tbg", "a"), ("tbg", "b")]
             + [("compare", "assembly", c, "nominal") for c in ("ptsmc", "pd", "smc")]
             + [("hold", "assembly")])
    clock = iter(range(100))
    monkeypatch.setattr(paper_report.time, "monotonic", lambda: float(next(clock)))
    lines, finished = [], []
    report = paper_report._task_reporter(runs, tasks, lambda name: lambda t, d: finished.append(name),
                                         lines.append, every_s=5.0)
    for done, index in enumerate(range(len(tasks)), start=1):
        report(done, len(tasks), index, {"duration": 1.0})
    assert finished == runs
    assert lines == ["[3/9] camera figure (c) done", "[5/9] TBG figure b done",
                     "[8/9] comparison on assembly: smc, nominal done",
                     "[9/9] the paper's hold formula (k_hold = k) on assembly done"]
