"""Parameter sweeps over (β, tf) in parallel worker processes (``ptint sweep``).

Each grid point is one simulation of the scenario with every segment's β and tf
replaced, run by a worker that builds its own diagram from the scenario *text*
(Drake diagrams do not pickle).  The points run on ``studies.runner``: local
worker processes (default), a Dask scheduler (``dask=ADDRESS``) or any
``concurrent.futures.Executor``.  When a point makes the last interception fall after
the scenario's end, the duration is extended to the last start + 2 tf.

A pick scenario (``pick``): β of every segment of every task, and tf of each task's
``approach`` (the interception of the moving part; the later segments move with it), the
duration extended to the plan's end + 0.5 s; ``e_tf`` is the largest over the segments and a
point is ``ok`` when every part is placed.
"""

from __future__ import annotations

import csv
import io
import time
from concurrent.futures import Executor
from pathlib import Path

import numpy as np

from ptint_drake.outputs.folder import write_text_atomic
from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, parse_scenario, validate
from ptint_drake.studies.runner import run_tasks

# Imported here, not in the worker function: forked workers then inherit them ready.
from ptint_drake.views.plots import plt, save
from ptint_drake.worlds.registry import world_of

COLUMNS = ("beta", "tf", "e0", "e_tf", "e_half", "hold", "peak_torque", "peak_torque_after_startup",
           "peak_jerk", "realtime_factor", "steps", "ok", "error")


def sweep_point(text: str, name: str, beta: float, tf: float) -> dict:
    """Simulate one grid point; returns a row of ``COLUMNS`` (``error`` set if it failed)."""
    row = {"beta": beta, "tf": tf, "error": ""}
    try:
        scenario = parse_scenario(text, name)
        return world_of(scenario).sweep_point(row, scenario, beta, tf, simulate, validate)
    except (ScenarioError, RuntimeError) as exc:
        row["error"] = " ".join(str(exc).split())[:200]
        row["ok"] = False
        return row


def run_sweep(loaded: LoadedScenario, betas, tfs, executor: Executor = None, workers: int = None,
              progress=None, dask: str = None) -> list[dict]:
    """Rows for the grid betas × tfs of the scenario ``loaded``, in grid order (the workers
    rebuild it from its text).  ``executor`` is used as given and
    left open; ``dask`` is a scheduler address; without either, ``workers`` local
    processes (default: CPU count).  ``progress(done, total)`` as rows arrive."""
    points = [(loaded.text, loaded.name, float(b), float(tf)) for b in betas for tf in tfs]
    report = (lambda done, total, index, row: progress(done, total)) if progress else None
    return run_tasks(sweep_point, points, workers=workers, dask=dask, executor=executor,
                     progress=report, folders=loaded.folders)


def write_csv(rows, path: Path) -> None:
    """sweep.csv (``COLUMNS``) written at once (``outputs.write_text_atomic``)."""
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=COLUMNS)
    writer.writeheader()
    for row in rows:
        writer.writerow({k: row.get(k, "") for k in COLUMNS})
    write_text_atomic(Path(path), text.getvalue())


def _frame(ax, label: str, betas, tfs) -> None:
    nt = len(tfs)
    ax.set_xticks(range(nt), [f"{tf:g}" for tf in tfs], rotation=45 if nt > 6 else 0)
    ax.set_yticks(range(len(betas)), [f"{b:g}" for b in betas])
    ax.set_title(label, fontsize=10)
    ax.tick_params(labelbottom=True, labelleft=True)
    ax.set_xlabel("$t_f$ [s]")
    ax.set_ylabel("β")


def _grid(lookup: dict, betas, tfs, value) -> np.ndarray:
    """value(row) on the β × tf grid (NaN where the point did not run)."""
    grid = np.full((len(betas), len(tfs)), np.nan)
    for i, b in enumerate(betas):
        for j, tf in enumerate(tfs):
            r = lookup.get((float(b), float(tf)))
            if r and not r.get("error"):
                grid[i, j] = value(r)
    return grid


def _metric_map(fig, ax, grid: np.ndarray, label: str, betas, tfs, fontsize: int) -> None:
    from matplotlib.colors import LogNorm  # noqa: PLC0415

    finite = grid[np.isfinite(grid)]
    norm = None
    if finite.size and finite.min() > 0 and finite.max() / finite.min() > 30:
        norm = LogNorm(finite.min(), finite.max())  # spans decades: colour by order of magnitude
    im = ax.imshow(grid, origin="lower", aspect="auto", cmap="viridis", norm=norm)
    _frame(ax, label, betas, tfs)
    cbar = fig.colorbar(im, ax=ax, shrink=0.9)
    cbar.ax.tick_params(labelsize=8)
    if grid.size <= 100 and finite.size:
        for i, j in zip(*np.nonzero(np.isfinite(grid))):
            r, g, b_, _ = im.cmap(im.norm(grid[i, j]))
            dark = 0.299 * r + 0.587 * g + 0.114 * b_ < 0.5
            ax.text(j, i, f"{grid[i, j]:.3g}", ha="center", va="center",
                    color="w" if dark else "k", fontsize=fontsize)


def heatmaps(rows, betas, tfs, out_dir: Path, title: str) -> list[str]:
    """One heat map per metric over (tf, β), plus a map of which points intercepted (the
    run's verdict, docs/results.md); returns the stems written.  The torque map shows the
    peak after start-up (the first 5 % of tf, where the first step dominates, left out)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap  # noqa: PLC0415

    metrics = (("e_tf", "|e(tf)| [mm]", 1e3), ("hold", "hold max |e| [mm]", 1e3),
               ("peak_torque_after_startup", "peak |τ| after start-up [N·m]", 1.0),
               ("peak_jerk", "peak |jerk| [m/s³]", 1.0), ("realtime_factor", "realtime factor [-]", 1.0))
    lookup = {(float(r["beta"]), float(r["tf"])): r for r in rows}
    nb, nt = len(betas), len(tfs)
    fontsize = 8 if max(nb, nt) <= 6 else 6
    fig, axes = plt.subplots(2, 3, figsize=(13.5, 7.2 + 0.15 * max(nb - 4, 0)),
                             layout="constrained", sharex=True, sharey=True)
    axes = axes.ravel()
    for ax, (key, label, scale) in zip(axes, metrics):
        grid = _grid(lookup, betas, tfs, lambda r: float(r[key]) * scale if r.get(key) not in (None, "")
                     else np.nan)
        _metric_map(fig, ax, grid, label, betas, tfs, fontsize)
    status = np.nan_to_num(_grid(lookup, betas, tfs, lambda r: 0.0 if r.get("ok") in (True, "True")
                                 else 1.0), nan=2.0)  # 0 intercepted, 1 missed, 2 error / not run
    ax = axes[len(metrics)]
    ax.imshow(status, origin="lower", aspect="auto", cmap=ListedColormap(["#4caf50", "#e53935", "#9e9e9e"]),
              norm=BoundaryNorm([-0.5, 0.5, 1.5, 2.5], 3))
    _frame(ax, "intercepted?", betas, tfs)
    if nb * nt <= 100:
        words = {0.0: "yes", 1.0: "missed", 2.0: "error"}
        for i in range(nb):
            for j in range(nt):
                ax.text(j, i, words[status[i, j]], ha="center", va="center", color="w",
                        fontsize=fontsize, fontweight="bold")
    fig.suptitle(f"{title}: {int(np.sum(status == 0))} of {nb * nt} points intercepted "
                 f"(|e(tf)| ≤ 1 mm, hold ≤ 3 mm, |e(tf/2)| ≥ |e0|/4)")
    save(fig, out_dir, "sweep")
    return ["sweep"]


def timed_sweep(text: str, name: str, betas, tfs, workers: int) -> float:
    """Wall seconds of a whole sweep with ``workers`` processes (pool start-up included)."""
    t0 = time.perf_counter()
    run_sweep(LoadedScenario.parse(text, name), betas, tfs, workers=workers)
    return time.perf_counter() - t0
