"""What ``ptint run`` and ``ptint diagram`` write: a run's folder and a diagram export.

``run_and_write`` simulates, and stages every file (series.npz, figures,
replay.html, metrics.json last) through ``outputs.staged_output``.
"""

from __future__ import annotations

import gc
import multiprocessing
import os
import re
import shutil
import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

from ptint_drake.outputs.folder import METRICS, SERIES, save_series, staged_output, write_json_atomic
from ptint_drake.simulation import build, simulate
from ptint_drake.simulation.scenario import Scenario, ScenarioError, dump_dataclass
from ptint_drake.studies.workers import fork_is_safe
from ptint_drake.worlds.registry import world_key, world_named, world_of


def run_and_write(scenario: Scenario, out_dir: Path, replay: bool = True, figures: bool = True,
                  progress=None, warn=None, svg: bool = False, workers: int | None = None) -> dict:
    """Simulate ``scenario`` and write its outputs into ``out_dir``; returns the metrics.
    ``warn(message)`` gets the warnings known before the simulation, before it starts.
    ``svg``: the figures as SVG too; ``workers``: processes drawing the figures and the
    replay (default: one per CPU; see ``draw_views``).  With figures to draw and a second
    CPU, the simulation runs in a forked process while this one prepares the figures
    (``simulate_beside``)."""
    prepare = None
    if figures and (workers or os.cpu_count() or 1) > 1:
        from ptint_drake.views.plots import preload as prepare  # noqa: PLC0415
    metrics, series = simulate_beside(scenario, prepare, progress=progress, warn=warn)
    run_json = run_metrics(scenario, metrics, figures)
    with staged_output(out_dir) as stage:
        save_series(stage / SERIES, series)
        draw_views(view_tasks(scenario, series, metrics, stage, figures=figures,
                              replay=replay, svg=svg), workers)
        write_json_atomic(stage / METRICS, run_json)
    return run_json


def _simulate_child(conn, scenario: Scenario, progress, warn) -> None:
    """The forked process of ``simulate_beside``: (True, (metrics, series)) or (False, the
    exception) on ``conn``."""
    import signal  # noqa: PLC0415

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    try:
        result = simulate(scenario, progress=progress, warn=warn)
        reply = (True, (result.metrics, result.series))
    except BaseException as exc:  # noqa: BLE001  (re-raised in the parent)
        reply = (False, exc)
    try:
        conn.send(reply)
    except Exception as exc:  # noqa: BLE001  (an unpicklable exception)
        conn.send((False, RuntimeError(f"simulation: {reply[1]!r} ({exc!r})"[:500])))


def simulate_beside(scenario: Scenario, prepare=None, **kwargs) -> tuple[dict, dict]:
    """(metrics, series) of ``simulate(scenario, **kwargs)``; when ``prepare`` is given and
    this process may fork (``can_fork``), the simulation runs in a forked process while this
    one calls ``prepare()`` (e.g. importing matplotlib: 1-2 s that then overlap the
    simulation instead of following it).  Its exceptions are raised here; Ctrl-C stops it."""
    if prepare is None or not can_fork():
        result = simulate(scenario, **kwargs)
        return result.metrics, result.series
    # fork, not forkserver: the child needs the scenario and this process's imports at no cost,
    # and the fork is safe (can_fork: no other Python thread, hence no lock held by one)
    ctx = multiprocessing.get_context("fork")
    conn, child_conn = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_simulate_child, args=(child_conn, scenario, kwargs.get("progress"),
                                                      kwargs.get("warn")), daemon=True)
    with frozen_heap():  # until the child is done: neither process copies the other's pages
        child.start()
        child_conn.close()
        try:
            prepare()
            ok, value = conn.recv()
            child.join(5.0)
        except EOFError:
            child.join(1.0)
            raise RuntimeError(f"the simulation's process died (exit code {child.exitcode})") from None
        finally:
            if child.is_alive():
                child.terminate()
                child.join()
            conn.close()
    if not ok:
        raise value
    return value


def run_metrics(scenario: Scenario, metrics: dict, figures: bool = True) -> dict:
    """metrics.json of a run: the simulation's metrics, the scenario as run, the figures' files."""
    metrics = dict(metrics)
    metrics["scenario_config"] = dump_dataclass(scenario)
    if figures:
        metrics["figures"] = world_of(scenario).figure_files(scenario)
    return metrics


def view_task(world: str, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple):
    """One figure or the replay of a run of world ``world`` (``World.draw_view``), written in
    ``stage``; module-level, so that a worker process can run it."""
    return world_named(world).draw_view(name, series, metrics, stage, title, args)


def view_tasks(scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool = True,
               replay: bool = True, svg: bool = False) -> list[tuple]:
    """``view_task`` arguments for a run's figures (PNG, and SVG when ``svg``) and its
    ``replay.html``, written in ``stage`` (the world's ``view_tasks``)."""
    world = world_of(scenario)
    key = world_key(scenario)
    return [(key, *task) for task in world.view_tasks(scenario, series, metrics, stage, figures, replay, svg)]


@contextmanager
def frozen_heap():
    """Fork inside this: the objects alive now stay out of the garbage collector's passes
    (``gc.freeze``) until it ends.  Otherwise a forked child's first full collection writes
    to the header of every object it inherited and so copies most pages of this process
    (~10,000 page faults a figure worker, 0.1-0.3 s each on these machines)."""
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def can_fork() -> bool:
    """Whether a forked worker is safe: this process runs one Python thread (``fork_is_safe``:
    no other thread can hold a lock the child would inherit locked; the command line's case,
    not a notebook's or a pytest-xdist worker's) and holds no Meshcat (its server threads are
    C++ threads: a fork would copy the ``Meshcat`` object without them, and a replay drawn in
    the child would wait on them forever).  Otherwise the caller works in this process."""
    replay = sys.modules.get("ptint_drake.views.replay")
    return fork_is_safe() and getattr(replay, "_MESHCAT", None) is None


def draw_views(tasks: list[tuple], workers: int | None = None) -> None:
    """Run ``view_task`` on each of ``tasks``.

    Each view is drawn on up to ``workers`` processes forked from this one (default: one
    per CPU) while this process waits: the figures cost matplotlib's layout, not
    arithmetic, and they are independent.  In a process with other threads (a notebook),
    or with one worker, or once this process made a Meshcat (``can_fork``), they are drawn
    here one after the other.  With workers, the replay's Meshcat lives in a worker, so this
    process stays fit to fork.
    """
    if any(not task[1].endswith("replay") for task in tasks):
        from ptint_drake.views.plots import preload  # noqa: PLC0415

        preload()  # once here, not in every worker
    workers = min(len(tasks), workers or os.cpu_count() or 1)
    if workers > 1 and can_fork():
        from ptint_drake.studies.runner import run_tasks  # noqa: PLC0415

        with frozen_heap():
            run_tasks(view_task, tasks, workers=workers, max_tasks_per_child=None)
    else:
        for task in tasks:
            view_task(*task)


def write_views(scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool = True,
                replay: bool = True, svg: bool = False, workers: int | None = None) -> list[str]:
    """The run's figures and replay in ``stage`` (``view_tasks``, ``draw_views``); returns
    the figure stems."""
    draw_views(view_tasks(scenario, series, metrics, stage, figures, replay, svg), workers)
    return [Path(f).stem for f in world_of(scenario).figure_files(scenario)] if figures else []


def normalize_graphviz_ids(text: str) -> str:
    """Renumber Drake's system ids (a process-wide counter) in order of appearance and
    sort each run of edge lines (Drake emits them in an order that varies by process).

    The same diagram then exports to the same text in any process, so the
    committed ``diagrams/`` can be compared with a fresh export.
    """
    mapping: dict = {}

    def renumber(match):
        key = match.group(2)
        mapping.setdefault(key, str(len(mapping)))
        return match.group(1) + mapping[key]

    lines = re.sub(r"(\bs|\b_|cluster)(\d+)", renumber, text).split("\n")
    out, edges = [], []
    for line in lines + [""]:
        if " -> " in line:
            edges.append(line)
            continue
        out.extend(sorted(edges))
        edges = []
        out.append(line)
    return "\n".join(out[:-1])


def write_diagram(scenario: Scenario, out_dir: Path) -> list[Path]:
    """The built diagram as ``NAME.dot`` and ``NAME.svg`` (Graphviz's ``dot``)."""
    dot_exe = shutil.which("dot")
    if dot_exe is None:
        raise ScenarioError("diagram: Graphviz's `dot` is not installed (apt-get install graphviz)")
    diagram = build(scenario, log=False).diagram
    text = normalize_graphviz_ids(diagram.GetGraphvizString(max_depth=1))
    out_dir = Path(out_dir)
    with staged_output(out_dir, additive=True) as stage:  # one pair of files per scenario
        dot_path = stage / f"{scenario.name}.dot"
        dot_path.write_text(text)
        svg = subprocess.run([dot_exe, "-Tsvg", str(dot_path)], check=True,
                             capture_output=True, text=True).stdout
        (stage / f"{scenario.name}.svg").write_text(svg)
    return [out_dir / f"{scenario.name}.dot", out_dir / f"{scenario.name}.svg"]
