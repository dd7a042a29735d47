"""Time two versions of ptint_drake against each other, alternating; prints JSON.

    python scripts/compare_versions.py [--old REF] [--new DIR] [--pairs 5]
                                       [--cases run,paper,realtime,robust] [--python PY]

``--old REF`` (default: the merge-base of HEAD with origin's default branch, else with
``main``) is exported with ``git archive`` into a temporary folder; ``--new`` is a source
tree (default: this working tree, uncommitted changes included).  Both run on ONE Python
environment (``--python``, default: the one running this script) with ``PYTHONPATH``
pointing at each tree's sources: the package is pure Python, so what differs between the
two is exactly the package's code, while Drake, NumPy, SciPy and matplotlib are the same
binaries (two virtual environments would measure two installs of the same wheels and take
minutes and gigabytes to build).  The script checks that each tree's ``ptint_drake``
imports from that tree.  If the new tree needs a package the old one does not, install it
in that environment (the old tree ignores it).  Use ``--python`` once per Drake end.

Each case runs old, new, old, new, … ``--pairs`` times (one pair = one old + one new,
back to back, so a change in the machine's load hits both), and reports the medians and
``speedup`` (> 1: the new version is faster):

- ``run``: wall time of ``ptint run curve_b075_tf15`` with its default outputs;
- ``paper``: wall time of ``ptint paper``;
- ``realtime/NAME``: ``sim.realtime_factor`` of metrics.json (SPEC 5.3, in-process end to end)
  of ``ptint run NAME --no-replay --no-figures`` for every bundled scenario without a camera
  (a continuous plant fed the true target) that both versions have; ``metrics_equal`` says
  whether every other metric of the two versions agrees within max(1 %, 1 µm) (timing fields left out);
- ``robust``: ``samples_per_s`` of ``ptint robust curve_b075_tf15 --samples 200 --workers 2``.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RUN_SCENARIO = "curve_b075_tf15"
TIMING_KEYS = ("wall", "realtime_factor")


def default_old_ref(repo: Path) -> str:
    """The commit where this branch left origin's default branch (or ``main``)."""
    for upstream in ("origin/HEAD", "origin/main", "origin/master", "main", "master"):
        found = subprocess.run(["git", "-C", str(repo), "merge-base", "HEAD", upstream],
                               capture_output=True, text=True)
        if found.returncode == 0:
            return found.stdout.strip()
    raise SystemExit("compare_versions: no upstream branch to take the merge-base with; give --old REF")


def export_tree(repo: Path, ref: str, into: Path) -> Path:
    """``ref``'s files (``git archive``) in ``into``; returns the folder."""
    into.mkdir(parents=True, exist_ok=True)
    archive = subprocess.run(["git", "-C", str(repo), "archive", "--format=tar", ref],
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return into


class Version:
    """One source tree run on the shared Python: ``ptint`` commands and their wall times."""

    def __init__(self, label: str, tree: Path, python: str, scratch: Path):
        self.label, self.tree, self.python, self.scratch = label, tree, python, scratch
        self.env = {"PYTHONPATH": str(tree), "PATH": "/usr/bin:/bin", "HOME": str(Path.home()),
                    "MPLBACKEND": "Agg", "PYTHONHASHSEED": "0"}
        where = subprocess.run([python, "-c", "import ptint_drake; print(ptint_drake.__file__)"],
                               env=self.env, cwd=scratch, capture_output=True, text=True,
                               check=True).stdout
        if not Path(where.strip()).resolve().is_relative_to(tree.resolve()):
            raise SystemExit(f"compare_versions: {label} imports ptint_drake from {where.strip()}, "
                             f"not from {tree}")

    def ptint(self, *args: str) -> float:
        """Run ``ptint ARGS`` (exit 0 or 1: a miss is a result); returns its wall time (s)."""
        t0 = time.perf_counter()
        done = subprocess.run([self.python, "-m", "ptint_drake", *args], env=self.env, cwd=self.scratch,
                              capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if done.returncode not in (0, 1):
            raise SystemExit(f"compare_versions: {self.label}: ptint {' '.join(args)} failed:\n"
                             f"{done.stderr[-2000:]}")
        return wall


def measure(version: Version, case: str, out: Path):
    """One sample of ``case``: (value, metrics or None)."""
    if case == "run":
        return version.ptint("run", RUN_SCENARIO, "--quiet", "--out", str(out)), None
    if case == "paper":
        return version.ptint("paper", "--quiet", "--out", str(out)), None
    if case == "robust":
        version.ptint("robust", RUN_SCENARIO, "--samples", "200", "--workers", "2", "--quiet",
                      "--out", str(out))
        return json.loads((out / "robust.json").read_text())["samples_per_s"], None
    name = case.split("/", 1)[1]
    version.ptint("run", name, "--no-replay", "--no-figures", "--quiet", "--out", str(out))
    metrics = json.loads((out / "metrics.json").read_text())
    return metrics["sim"]["realtime_factor"], metrics


def _numbers(value, path=""):
    """Every numeric leaf of a metrics tree as (path, value), timing fields left out."""
    if isinstance(value, dict):
        for key, item in value.items():
            if not any(word in key for word in TIMING_KEYS):
                yield from _numbers(item, f"{path}.{key}")
    elif isinstance(value, list):
        for i, item in enumerate(value):
            yield from _numbers(item, f"{path}[{i}]")
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield path, float(value)


def metrics_differences(old: dict, new: dict) -> list[str]:
    """The metrics that differ by more than max(1 %, 1 µm), or exist in one version only
    among the fields both versions know (a new field is not a difference)."""
    a, b = dict(_numbers(old)), dict(_numbers(new))
    return [key for key in a if key in b and abs(a[key] - b[key]) > max(0.01 * abs(a[key]), 1e-6)]


def continuous_scenarios(tree: Path) -> list[str]:
    """The bundled scenarios without a camera (no ``measurement:`` section)."""
    return sorted(p.stem for p in (tree / "ptint_drake" / "scenarios").glob("*.yaml")
                  if "\nmeasurement:" not in "\n" + p.read_text())


def compare(old: Version, new: Version, cases: list[str], pairs: int, log) -> dict:
    """Every case, ``pairs`` times old then new; the medians and the speedups."""
    samples = {case: {"old": [], "new": []} for case in cases}
    metrics = {}
    for i in range(pairs):
        for case in cases:
            for version in (old, new):
                out = version.scratch / f"{case.replace('/', '_')}_{i}"
                value, m = measure(version, case, out)
                samples[case][version.label].append(value)
                if m is not None:
                    metrics.setdefault(case, {})[version.label] = m
                log(f"pair {i + 1}/{pairs} {case} {version.label}: {value:.4g}")
    report = {}
    for case, s in samples.items():
        med_old, med_new = statistics.median(s["old"]), statistics.median(s["new"])
        higher_is_better = case == "robust" or case.startswith("realtime/")
        row = {"unit": "samples/s" if case == "robust" else ("realtime factor" if higher_is_better
                                                             else "s wall"),
               "old_median": med_old, "new_median": med_new,
               "speedup": (med_new / med_old) if higher_is_better else (med_old / med_new),
               "old": s["old"], "new": s["new"]}
        if case in metrics:
            diff = metrics_differences(metrics[case]["old"], metrics[case]["new"])
            row["metrics_equal"] = not diff
            if diff:
                row["metrics_differing"] = diff[:20]
        report[case] = row
    return report


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--old", help="git ref of the old version (default: merge-base with origin)")
    parser.add_argument("--new", default=str(ROOT), help="source tree of the new version")
    parser.add_argument("--pairs", type=int, default=5, help="old/new pairs per case (default 5)")
    parser.add_argument("--cases", default="run,paper,realtime,robust",
                        help="comma list of run, paper, realtime, robust, realtime/NAME")
    parser.add_argument("--python", default=sys.executable, help="the Python (with Drake) to run")
    args = parser.parse_args(argv)
    if "/" in args.python:  # a path: absolute (each version runs in its own folder); a venv's
        args.python = str(Path(args.python).absolute())  # symlink is kept, not resolved
    if shutil.which(args.python) is None:
        raise SystemExit(f"compare_versions: --python {args.python}: no such executable")
    new_tree = Path(args.new).resolve()
    ref = args.old or default_old_ref(new_tree)
    with tempfile.TemporaryDirectory(prefix="ptint-compare-") as tmp:
        tmp = Path(tmp)
        old_tree = export_tree(new_tree, ref, (tmp / "old_src").resolve())
        both = sorted(set(continuous_scenarios(new_tree)) & set(continuous_scenarios(old_tree)))
        cases = []
        for case in args.cases.split(","):
            cases += [f"realtime/{n}" for n in both] if case == "realtime" else [case]
        for label in ("old", "new"):
            (tmp / label).mkdir(exist_ok=True)
        old = Version("old", old_tree, args.python, tmp / "old")
        new = Version("new", new_tree, args.python, tmp / "new")
        log = lambda message: print(message, file=sys.stderr, flush=True)  # noqa: E731
        report = compare(old, new, cases, args.pairs, log)
    python = subprocess.run([args.python, "-c", "import sys, importlib.metadata as m; "
                             "print(sys.version.split()[0], m.version('drake'))"],
                            capture_output=True, text=True, env={"PATH": "/usr/bin:/bin"}).stdout.split()
    print(json.dumps({"old": ref, "new": str(new_tree), "python": python[:1], "drake": python[1:],
                      "pairs": args.pairs, "cases": report}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
