"""Show that every bundled scenario's metrics.json is value-identical between two revisions.

    python scripts/metrics_identity.py [--base REV] [--head REV] [--scenarios NAME ...]
                                       [--jobs N] [--cache DIR] [--out FILE.json]

``--base REV`` (default ``a6270f8``) and ``--head REV`` (default: the working tree of the
checkout this script lives in, uncommitted changes included) are revisions of that checkout's
repository.  A revision is checked out with ``git worktree add --detach`` into a temporary folder
(removed at the end, also on Ctrl-C or SIGTERM); only when one of its scenarios must actually run.
Each scenario runs with that tree's own command line, ``python -m ptint_drake run NAME --out DIR``
(plus ``--no-figures --no-replay --quiet`` when the tree's ``run --help`` offers them: only
metrics.json matters), on the Python running this script, with the tree first on ``sys.path``
and setuptools' editable-install finder removed, so an editable install of another checkout
cannot shadow it (each child checks that ``ptint_drake`` was imported from its tree).  Before its
scenarios, each tree compiles its numba kernels once with its own warm-up module (``python -m
ptint_drake.cli.warm_up``, or ``ptint_drake.warm_up`` in older trees; ``--no-warm-up`` to skip),
so the runs' wall times are comparable and two runs do not compile the same kernels at once.

``--scenarios``: default every bundled scenario of either side (``ptint_drake/scenarios/*.yaml``);
a scenario bundled on one side only is reported (``only_in``) and counts as a difference; a name
bundled on neither side is a bad argument.  ``--jobs N`` (default 2) runs at a time.  ``--cache
DIR`` keeps each revision's outputs in ``DIR/<commit sha>/<scenario>/`` and reuses them on a
later call (same sha, same ``run`` flags, exit code 0 or 1); the working tree is never cached,
nor the head when it is the base's commit (then the two sides are two independent runs of one
commit: a determinism check).

Comparison (``compare``): recursive over dicts and lists; numbers exactly (``1`` and ``1.0`` are
reported as a type change, NaN equals NaN, each differing number with its relative difference
|a - b| / max(|a|, |b|)); strings, booleans and nulls exactly; a key or list item present on one
side only is a difference.  Ignored, and only these (``IGNORED``): the values of the timing fields
of the top-level ``sim`` block, which measure the machine, not the computation:

- ``sim.wall_time_s``, ``sim.simulation_wall_time_s``: ``time.perf_counter()`` differences
  (``simulation.py`` ``_sim_info``, ``pick/run.py`` ``_pick_sim_info``);
- ``sim.realtime_factor``, ``sim.simulation_realtime_factor``: ``simulated_s`` divided by those.

Their presence is still checked (a key missing on one side is a difference); every other field of
``sim`` (``simulated_s``, ``steps``, ``derivative_evaluations``, the integrator, ...) is compared.
The exit code of ``ptint run`` and the set of file names written in the output folder are
compared too.

Cost (a6270f8, 2 busy cores): a fresh worktree's warm-up 3.5-7.5 min, then the 18 scenarios 4-52 s
each (about 2.5 min per side with 2 jobs); a cached base needs neither.  Three independent runs
of a6270f8 (two worktrees and a working tree) gave value-identical metrics.json for every scenario.

Output: JSON on stdout (and in ``--out FILE.json``): per scenario ``identical``, the differing
paths with both values, the files, exit codes and wall times of each side; a ``summary``.  Exit
code 0 when every scenario is identical, 1 when any differs (or could not run), 2 on a bad
argument (one line naming it), 130 on Ctrl-C.  Progress goes to stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_BASE = "a6270f8"
PROG = "metrics_identity"
SCENARIO_DIR = Path("ptint_drake") / "scenarios"
# (path in metrics.json) -> why it is not compared
IGNORED: dict[tuple[str, ...], str] = {
    ("sim", "wall_time_s"): "wall time of simulation, telemetry and metrics (time.perf_counter)",
    ("sim", "simulation_wall_time_s"): "wall time of the simulation alone (time.perf_counter)",
    ("sim", "realtime_factor"): "simulated_s / wall_time_s",
    ("sim", "simulation_realtime_factor"): "simulated_s / simulation_wall_time_s",
}
OPTIONAL_FLAGS = ("--no-figures", "--no-replay", "--quiet")
# Runs `python -m ptint_drake ARGS` with TREE first on sys.path and the editable finders gone.
BOOT = """\
import runpy, sys
from pathlib import Path
tree = Path(sys.argv.pop(1)).resolve()
sys.meta_path[:] = [f for f in sys.meta_path if not getattr(f, '__module__', '').startswith('__editable__')]
sys.path.insert(0, str(tree))
import ptint_drake
where = Path(ptint_drake.__file__).resolve()
if not where.is_relative_to(tree):
    sys.exit(f'metrics_identity: ptint_drake imported from {where}, not from {tree}')
module = sys.argv.pop(1)
sys.argv[0] = 'ptint'
runpy.run_module(module, run_name='__main__', alter_sys=True)
"""


class BadArgument(Exception):
    """A bad command-line argument: one line, exit 2."""


class Interrupted(Exception):
    """SIGTERM, turned into an exception so that the clean-up runs."""


# ----------------------------------------------------------------------------- comparison

def _path_text(path: tuple) -> str:
    text = ""
    for part in path:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "<root>"


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def relative_difference(a: float, b: float) -> float:
    """|a - b| / max(|a|, |b|): 0 when equal (NaN and NaN included), inf when one side is not
    finite or NaN and the other differs."""
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    if not (math.isfinite(a) and math.isfinite(b)):
        return math.inf
    return abs(a - b) / max(abs(a), abs(b))


def compare(base: Any, head: Any, path: tuple = (),
            ignored: dict[tuple[str, ...], str] | None = None) -> list[dict]:
    """The differences between two JSON values (``base``, ``head``), recursively: a list of
    ``{"path", "kind", "base", "head"}`` (``kind``: ``value``, ``type``, ``missing_in_base``,
    ``missing_in_head``, ``length``; ``rel_diff`` for two numbers).  ``ignored`` (default
    ``IGNORED``): paths whose values are not compared (their presence is)."""
    ignored = IGNORED if ignored is None else ignored
    if path in ignored:
        return []
    where = _path_text(path)
    if isinstance(base, dict) and isinstance(head, dict):
        out = []
        for key in list(base) + [k for k in head if k not in base]:
            if key not in head:
                out.append({"path": _path_text(path + (key,)), "kind": "missing_in_head",
                            "base": base[key], "head": None})
            elif key not in base:
                out.append({"path": _path_text(path + (key,)), "kind": "missing_in_base",
                            "base": None, "head": head[key]})
            else:
                out += compare(base[key], head[key], path + (key,), ignored)
        return out
    if isinstance(base, list) and isinstance(head, list):
        out = []
        for i, (a, b) in enumerate(zip(base, head)):
            out += compare(a, b, path + (i,), ignored)
        if len(base) != len(head):
            out.append({"path": where, "kind": "length", "base": len(base), "head": len(head)})
        return out
    if _is_number(base) and _is_number(head):
        if type(base) is not type(head):
            return [{"path": where, "kind": "type", "base": base, "head": head,
                     "rel_diff": relative_difference(float(base), float(head))}]
        if base == head or (isinstance(base, float) and math.isnan(base) and math.isnan(head)):
            return []
        return [{"path": where, "kind": "value", "base": base, "head": head,
                 "rel_diff": relative_difference(float(base), float(head))}]
    if type(base) is not type(head):
        return [{"path": where, "kind": "type", "base": base, "head": head}]
    if base != head:
        return [{"path": where, "kind": "value", "base": base, "head": head}]
    return []


def additions_only(differences: list[dict], base: Any, head: Any) -> bool:
    """True when every difference only adds to the base (``values_identical``): a key present in
    the head alone (a new metric, a new configuration field echoed in ``scenario_config``), or
    lines added to a ``warnings…`` list that keeps every base line in its order (or a count of
    them, ``warnings_before_run``, that grew).  Every other value of the base is then the
    head's, bit for bit."""
    for d in differences:
        if d["kind"] == "missing_in_base":
            continue
        keys = d["path"].replace("[", ".[").split(".")
        at = next((i for i, k in enumerate(keys) if k.startswith("warnings")), None)
        if at is None:
            return False
        key = ".".join(keys[:at + 1])
        lines_base, lines_head = _at_text(base, key), _at_text(head, key)
        if isinstance(lines_base, int) and isinstance(lines_head, int):  # a count of warnings
            if lines_head < lines_base:
                return False
        elif not (isinstance(lines_base, list) and isinstance(lines_head, list)
                  and _subsequence(lines_base, lines_head)):
            return False
    return True


def _at_text(tree: Any, where: str) -> Any:
    """The value at a ``_path_text`` path of dict keys (``a.b.warnings``)."""
    for key in where.split("."):
        if not isinstance(tree, dict) or key not in tree:
            return None
        tree = tree[key]
    return tree


def _subsequence(short: list, long: list) -> bool:
    it = iter(long)
    return all(any(x == y for y in it) for x in short)


def max_relative_difference(differences: list[dict]) -> float | None:
    """The largest ``rel_diff`` of ``differences`` (None when none has one)."""
    values = [d["rel_diff"] for d in differences if "rel_diff" in d]
    return max(values) if values else None


def json_safe(value: Any) -> Any:
    """``value`` with non-finite floats as the strings ``NaN``, ``Infinity``, ``-Infinity``
    (strict JSON)."""
    if isinstance(value, float) and not math.isfinite(value):
        return "NaN" if math.isnan(value) else ("Infinity" if value > 0 else "-Infinity")
    if isinstance(value, dict):
        return {k: json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_safe(v) for v in value]
    return value


def output_files(folder: Path) -> list[str]:
    """The files under ``folder``, as sorted relative paths."""
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())


# ----------------------------------------------------------------------------- revisions and runs

def git(*args: str, cwd: Path = ROOT, check: bool = True) -> str:
    done = subprocess.run(["git", "-C", str(cwd), *args], capture_output=True, text=True)
    if check and done.returncode:
        raise RuntimeError(f"git {' '.join(args)}: {done.stderr.strip()}")
    return done.stdout.strip() if done.returncode == 0 else ""


@dataclass
class Side:
    """One side of the comparison: a commit (``sha``) or the working tree (``sha`` None)."""

    label: str
    rev: str
    sha: str | None
    tree: Path | None = None  # the source tree, once there is one
    flags: list[str] | None = None
    warm_up_s: float | None = None
    scenarios: list[str] = field(default_factory=list)

    @property
    def description(self) -> dict:
        head = git("rev-parse", "HEAD")
        if self.sha is None:
            dirty = bool(git("status", "--porcelain", "--untracked-files=no"))
            return {"rev": "working tree", "path": str(ROOT), "HEAD": head, "uncommitted_changes": dirty}
        return {"rev": self.rev, "sha": self.sha}


def resolve(rev: str, option: str) -> str:
    sha = git("rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}", check=False)
    if not sha:
        raise BadArgument(f"argument {option}: {rev!r} is not a commit of {ROOT}")
    return sha


def bundled(side: Side) -> list[str]:
    """The bundled scenario names of a side (without checking it out)."""
    if side.sha is None:
        return sorted(p.stem for p in (ROOT / SCENARIO_DIR).glob("*.yaml"))
    names = git("ls-tree", "--name-only", side.sha, f"{SCENARIO_DIR.as_posix()}/").splitlines()
    return sorted(Path(n).stem for n in names if n.endswith(".yaml"))


class Runner:
    """Runs child processes (each in its own process group, so that all of it can be stopped)."""

    def __init__(self, python: str):
        self.python = python
        self._live: set[subprocess.Popen] = set()
        self._lock = threading.Lock()
        self.stopping = False

    def run(self, tree: Path, args: list[str], module: str = "ptint_drake") -> tuple[int, str, float]:
        """``python -m MODULE ARGS`` of ``tree``: (exit code, stderr tail, wall s)."""
        env = dict(os.environ, PYTHONPATH=str(tree), MPLBACKEND="Agg")
        t0 = time.perf_counter()
        with self._lock:
            if self.stopping:
                raise KeyboardInterrupt
            proc = subprocess.Popen([self.python, "-c", BOOT, str(tree), module, *args], cwd=tree,
                                    env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                    start_new_session=True)
            self._live.add(proc)
        try:
            out, err = proc.communicate()
        finally:
            with self._lock:
                self._live.discard(proc)
        return proc.returncode, (out + err)[-3000:], time.perf_counter() - t0

    def stop_all(self) -> None:
        with self._lock:
            self.stopping = True
            live = list(self._live)
        for proc in live:
            try:
                os.killpg(proc.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        for proc in live:
            try:
                proc.wait(10)
            except subprocess.TimeoutExpired:
                try:
                    os.killpg(proc.pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass


def run_flags(runner: Runner, tree: Path) -> list[str]:
    """The options of ``OPTIONAL_FLAGS`` that the tree's ``ptint run`` has."""
    code, text, _ = runner.run(tree, ["run", "--help"])
    if code != 0:
        raise RuntimeError(f"`ptint run --help` of {tree} failed: {text}")
    return [flag for flag in OPTIONAL_FLAGS if flag in text]


def cached_run(cache: Path | None, side: Side, name: str) -> dict | None:
    """The cached run of ``name`` on ``side`` (None when there is none usable)."""
    if cache is None or side.sha is None:
        return None
    info_file = cache / side.sha / f"{name}.json"
    if not info_file.is_file():
        return None
    info = json.loads(info_file.read_text())
    folder = cache / side.sha / name
    if info.get("exit_code") not in (0, 1) or not folder.is_dir():
        return None
    if side.flags is not None and info.get("flags") != side.flags:
        return None
    return info | {"folder": str(folder), "cached": True}


def run_scenario(runner: Runner, side: Side, name: str, scratch: Path, cache: Path | None) -> dict:
    """Run ``name`` on ``side``; with a cache (and a commit), store the outputs there."""
    if cache is not None and side.sha is not None:
        final = cache / side.sha / name
        stage = cache / side.sha / f".{name}.{side.label}.{os.getpid()}.tmp"
    else:
        final = stage = scratch / side.label / name
    shutil.rmtree(stage, ignore_errors=True)
    stage.parent.mkdir(parents=True, exist_ok=True)
    code, tail, wall = runner.run(side.tree, ["run", name, "--out", str(stage), *side.flags])
    info = {"exit_code": code, "wall_s": round(wall, 3), "flags": side.flags, "sha": side.sha}
    if code not in (0, 1):
        info["error"] = tail
    if stage != final:
        if code in (0, 1):
            shutil.rmtree(final, ignore_errors=True)
            stage.rename(final)
            (final.parent / f"{name}.json").write_text(json.dumps(info, indent=1) + "\n")
        else:
            shutil.rmtree(stage, ignore_errors=True)
    return info | {"folder": str(final), "cached": False}


def load_metrics(run: dict) -> tuple[dict | None, str | None]:
    file = Path(run["folder"]) / "metrics.json"
    if not file.is_file():
        return None, f"no metrics.json (exit code {run['exit_code']})"
    try:
        return json.loads(file.read_text()), None
    except ValueError as exc:
        return None, f"metrics.json is not JSON: {exc}"


def compare_runs(base: dict, head: dict) -> dict:
    """The comparison of two runs of one scenario (``run_scenario`` results)."""
    row: dict[str, Any] = {"identical": True, "differences": []}
    base_metrics, base_error = load_metrics(base)
    head_metrics, head_error = load_metrics(head)
    if base_error or head_error:
        row["identical"] = False
        row["errors"] = {k: v for k, v in (("base", base_error or base.get("error")),
                                           ("head", head_error or head.get("error"))) if v}
    else:
        row["differences"] = compare(base_metrics, head_metrics)
        row["identical"] = not row["differences"]
        row["values_identical"] = additions_only(row["differences"], base_metrics, head_metrics)
        row["max_rel_diff"] = max_relative_difference(row["differences"])
        row["ignored_values"] = {_path_text(p): [_get(base_metrics, p), _get(head_metrics, p)]
                                 for p in IGNORED if _get(base_metrics, p) is not None}
    if base["exit_code"] != head["exit_code"]:
        row["identical"] = row["values_identical"] = False
    files = {s: output_files(Path(r["folder"])) if Path(r["folder"]).is_dir() else []
             for s, r in (("base", base), ("head", head))}
    only_base = sorted(set(files["base"]) - set(files["head"]))
    only_head = sorted(set(files["head"]) - set(files["base"]))
    row["files"] = {"identical": not only_base and not only_head, "names": files["base"]}
    if only_base or only_head:
        row["identical"] = False
        row["values_identical"] = row.get("values_identical", False) and not only_base
        row["files"] |= {"only_in_base": only_base, "only_in_head": only_head}
    row["exit_code"] = {"base": base["exit_code"], "head": head["exit_code"]}
    row["run_wall_s"] = {"base": base["wall_s"], "head": head["wall_s"]}
    row["cached"] = {"base": base["cached"], "head": head["cached"]}
    return row


def _get(tree: Any, path: tuple) -> Any:
    for part in path:
        if not isinstance(tree, dict) or part not in tree:
            return None
        tree = tree[part]
    return tree


# ----------------------------------------------------------------------------- main

class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # one line, no usage
        raise BadArgument(message)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    parser = _Parser(prog=PROG, description=__doc__.split("\n\n")[0])
    parser.add_argument("--base", default=DEFAULT_BASE, help=f"base revision (default {DEFAULT_BASE})")
    parser.add_argument("--head", help="head revision (default: the working tree of this checkout)")
    parser.add_argument("--scenarios", nargs="+", metavar="NAME", help="default: every bundled one")
    parser.add_argument("--jobs", default=2, type=_positive, help="runs at a time (default 2)")
    parser.add_argument("--cache", type=Path, help="keep and reuse each commit's outputs here")
    parser.add_argument("--out", type=Path, help="also write the JSON report to this file")
    parser.add_argument("--no-warm-up", action="store_true",
                        help="do not compile each tree's numba kernels before its runs")
    args = parser.parse_args(argv)
    if args.out is not None and not args.out.absolute().parent.is_dir():
        raise BadArgument(f"argument --out: folder {args.out.absolute().parent} does not exist")
    if args.cache is not None:
        try:
            args.cache.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise BadArgument(f"argument --cache: {exc}") from None
        args.cache = args.cache.resolve()
    return args


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not >= 1")
    return value


def _sigterm(signum, frame):
    raise Interrupted


def warm_up(runner: Runner, side: Side, log: Callable[[str], None]) -> None:
    """Compile the tree's numba kernels with its own warm-up module (where the tree has one)."""
    for module in ("cli.warm_up", "warm_up", "systems.warm_up"):
        if (side.tree / "ptint_drake" / f"{module.replace('.', '/')}.py").is_file():
            code, tail, side.warm_up_s = runner.run(side.tree, [], f"ptint_drake.{module}")
            log(f"{side.label}: warm-up {side.warm_up_s:.1f} s (exit code {code})")
            return


def identity(args: argparse.Namespace, log: Callable[[str], None]) -> dict:
    """The report of the comparison ``args`` asks for."""
    t_start = time.perf_counter()
    sides = [Side("base", args.base, resolve(args.base, "--base")),
             Side("head", args.head, resolve(args.head, "--head")) if args.head
             else Side("head", "working tree", None, tree=ROOT)]
    names = {s.label: bundled(s) for s in sides}
    wanted = args.scenarios or sorted(set(names["base"]) | set(names["head"]))
    unknown = [n for n in wanted if n not in names["base"] and n not in names["head"]]
    if unknown:
        raise BadArgument(f"argument --scenarios: {', '.join(unknown)}: bundled in neither revision")
    for side in sides:
        side.scenarios = [n for n in wanted if n in names[side.label]]
    # one commit on both sides: the head runs afresh (two independent runs: a determinism check)
    caches = {"base": args.cache, "head": None if sides[1].sha == sides[0].sha else args.cache}
    runner = Runner(sys.executable)
    scratch = Path(tempfile.mkdtemp(prefix="metrics_identity_"))
    worktrees: list[Path] = []
    runs: dict[tuple[str, str], dict] = {}
    previous = signal.signal(signal.SIGTERM, _sigterm)
    try:
        todo = []
        for side in sides:
            for name in side.scenarios:
                hit = cached_run(caches[side.label], side, name)
                if hit is not None:
                    runs[side.label, name] = hit
                    log(f"{side.label} {name}: cached ({hit['wall_s']:.1f} s when run)")
                else:
                    todo.append((side, name))
        needed = [s for s in sides if any(t[0] is s for t in todo)]
        for side in needed:
            if side.tree is None:
                side.tree = scratch / f"tree_{side.label}"
                worktrees.append(side.tree)
                git("worktree", "add", "--detach", str(side.tree), side.sha)
        pool = ThreadPoolExecutor(max_workers=args.jobs)
        try:
            for side, flags in zip(needed, pool.map(lambda s: run_flags(runner, s.tree), needed)):
                side.flags = flags
            if not args.no_warm_up:
                list(pool.map(lambda side: warm_up(runner, side, log), needed))

            def one(item: tuple[Side, str]) -> None:
                side, name = item
                run = run_scenario(runner, side, name, scratch, caches[side.label])
                runs[side.label, name] = run
                log(f"{side.label} {name}: exit code {run['exit_code']}, {run['wall_s']:.1f} s")
            list(pool.map(one, todo))
            return report(sides, wanted, runs, t_start)  # before the scratch folder goes
        except BaseException:
            runner.stop_all()  # before the pool waits for its threads: they wait for the children
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)
    except Interrupted:
        raise KeyboardInterrupt from None
    finally:
        signal.signal(signal.SIGTERM, previous)
        for tree in worktrees:
            git("worktree", "remove", "--force", str(tree), check=False)
            if tree.exists():  # not a worktree (yet): its folder, then git's record of it
                shutil.rmtree(tree, ignore_errors=True)
                git("worktree", "prune", check=False)
        shutil.rmtree(scratch, ignore_errors=True)


def report(sides: list[Side], wanted: list[str], runs: dict[tuple[str, str], dict], t_start: float) -> dict:
    """The JSON report: each scenario's comparison (``compare_runs``) and a summary."""
    scenarios, summary = {}, {"identical": [], "differing": [], "values_identical": [], "only_in_base": [],
                              "only_in_head": [], "could_not_run": []}
    for name in wanted:
        if ("base", name) not in runs or ("head", name) not in runs:
            side = "base" if ("base", name) in runs else "head"
            scenarios[name] = {"identical": False, "only_in": side}
            summary[f"only_in_{side}"].append(name)
            continue
        row = compare_runs(runs["base", name], runs["head", name])
        scenarios[name] = row
        if "errors" in row:
            summary["could_not_run"].append(name)
        summary["identical" if row["identical"] else "differing"].append(name)
        if row.get("values_identical"):
            summary["values_identical"].append(name)
    walls = {name: row["run_wall_s"] for name, row in scenarios.items() if "run_wall_s" in row}
    return {
        "base": sides[0].description, "head": sides[1].description,
        "python": sys.version.split()[0],
        "ignored": {_path_text(p): why for p, why in IGNORED.items()},
        "run_flags": {s.label: s.flags or next((r["flags"] for (label, _), r in runs.items()
                                                 if label == s.label), None) for s in sides},
        "warm_up_s": {s.label: s.warm_up_s for s in sides},
        "scenarios": scenarios,
        "summary": {"all_identical": all(r["identical"] for r in scenarios.values()),
                    "scenarios": len(scenarios), **summary,
                    "max_rel_diff": max((r["max_rel_diff"] for r in scenarios.values()
                                         if r.get("max_rel_diff") is not None), default=None),
                    "run_wall_s": walls, "total_wall_s": round(time.perf_counter() - t_start, 1)},
    }


def main(argv: list[str] | None = None) -> int:
    try:
        args = parse_args(argv)
        report = identity(args, lambda message: print(f"{PROG}: {message}", file=sys.stderr, flush=True))
    except BadArgument as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted; temporary worktrees removed", file=sys.stderr)
        return 130
    text = json.dumps(json_safe(report), indent=1, allow_nan=False)
    print(text)
    if args.out is not None:
        args.out.write_text(text + "\n")
    return 0 if report["summary"]["all_identical"] else 1


if __name__ == "__main__":
    sys.exit(main())
