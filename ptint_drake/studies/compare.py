"""Controllers side by side (``ptint compare``): the same plant, targets and metrics for each.

Every controller × plant variant is one run of the scenario with
``controller.type`` replaced and the variant applied to the simulated plant
(``scenario.apply_variant``); the controller is never told the variant.  The
rows hold the per-segment metrics of ``metrics.py`` (the one verdict, with the
scenario's own criteria) and, for the figure, |e(t)| and the applied torque
resampled on a fixed grid.

Each worker builds its own diagram from the scenario *text* (Drake diagrams do
not pickle).  ``ptint compare`` exits 0 when every run completed: a miss is a
result, counted in the summary line.
"""

from __future__ import annotations

import copy
import csv
import dataclasses
import io
import math
import time
from pathlib import Path

import numpy as np

from ptint_drake.controllers import CONTROLLERS
from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, apply_variant, parse_scenario
from ptint_drake.studies.runner import run_tasks
from ptint_drake.verdict.metrics import ROTATION_KEYS, Reason
from ptint_drake.views.plots import plt, save
from ptint_drake.worlds.registry import world_of

DEFAULT_CONTROLLERS = CONTROLLERS  # every registered controller
DEFAULT_VARIANTS = ("nominal", "mass_x0.7", "mass_x1.5")
SEGMENT_KEYS = ("e0_norm", "e_half_norm", "e_tf_norm", "edot_tf_norm", "e_hold_max_norm", "t_arrive")
_GRID_POINTS = 600


def with_controller(scenario, controller: str):
    """The scenario with ``controller.type`` replaced (a plugin keeps the file's ``params``; a
    registered controller gets none)."""
    out = copy.deepcopy(scenario)
    out.controller.type = controller
    if controller in CONTROLLERS:
        out.controller.params = {}
    return world_of(out).compare_scenario(out, controller)


def compare_run(text: str, name: str, controller: str, variant: str) -> dict:
    """One row: ``controller`` on plant ``variant`` (runs in a worker process)."""
    scenario = apply_variant(with_controller(parse_scenario(text, name), controller), variant)
    row = {"controller": controller, "variant": variant}
    try:
        result = simulate(scenario, check=False)
    except (ScenarioError, RuntimeError, ValueError) as exc:
        reason = Reason(None, "error", " ".join(str(exc).split())[:300])
        return row | {"ok": False, "status": "error", "reasons": [str(reason)],
                      "reason_codes": [reason.as_dict()], "torque_peak_max": None, "segments": []}
    m, series = result.metrics, result.series
    own = world_of(scenario).compare_row(m, series)
    if own is not None:
        return row | own
    t = series["t"]
    grid = np.linspace(0.0, scenario.duration, _GRID_POINTS)
    e_norm = np.linalg.norm(series["e_true"], axis=1)
    tau = np.abs(series["tau_applied"]).max(axis=1)
    return row | {
        "ok": m["status"] == "ok", "status": m["status"], "reasons": m["reasons"],
        "reason_codes": m["reason_codes"],
        "torque_peak_max": float(max(m["torque_peak"])),
        "torque_peak_after_startup_max": float(max(m["torque_peak_after_startup"])),
        "segments": [{k: seg.get(k) for k in SEGMENT_KEYS + ROTATION_KEYS} for seg in m["segments"]],
        "notes": m["controller"]["notes"], "model_based": m["controller"]["model_based"],
        "realtime_factor": m["sim"]["realtime_factor"],
        "curve": {"t": grid.tolist(), "e": np.interp(grid, t, e_norm).tolist(),
                  "tau": np.interp(grid, t, tau).tolist()},
    }


def run_compare(loaded: LoadedScenario, controllers=DEFAULT_CONTROLLERS, variants=DEFAULT_VARIANTS,
                workers=None, dask=None, progress=None) -> dict:
    """Every controller × variant of the scenario ``loaded`` (the workers rebuild it from its
    text); the content of compare.json (rows keep their curves)."""
    t0 = time.perf_counter()
    tasks = [(loaded.text, loaded.name, c, v) for c, v in pairs(controllers, variants)]
    rows = run_tasks(compare_run, tasks, workers=workers, dask=dask, progress=progress,
                     folders=loaded.folders)
    return comparison(loaded.scenario, loaded.name, controllers, variants, rows,
                      time.perf_counter() - t0)


def pairs(controllers, variants) -> list:
    """(controller, variant) in the order of the rows: variant by variant."""
    return [(c, v) for v in variants for c in controllers]


def comparison(scenario, name: str, controllers, variants, rows: list, wall_time_s: float) -> dict:
    """compare.json's content from the rows of ``pairs(controllers, variants)``."""
    return {"scenario": name, "controllers": list(controllers), "variants": list(variants),
            "segments": [{"start": i.start, "tf": i.tf, "beta": i.beta} for i in scenario.interceptions],
            "criteria": dataclasses.asdict(scenario.criteria),
            "wall_time_s": wall_time_s, "rows": rows}


def _mm(value) -> str:
    return "–" if value is None else f"{value * 1e3:.3g}"


def _s(value) -> str:
    return "never" if value is None else f"{value:.2f}"


def _torque(value) -> str:
    return "–" if value is None else f"{value:.2f}"


def table_rows(result: dict) -> list[dict]:
    """Flat rows (one per controller × variant × segment) for the CSV and the Markdown table."""
    out = []
    for row in result["rows"]:
        reasons = [Reason.from_dict(r) for r in row["reason_codes"]]
        for i, seg in enumerate(row["segments"] or [{}]):
            own = [r.code for r in reasons if r.segment == i]
            other = [str(r) for r in reasons if r.segment is None]  # failed/error: the message
            out.append({"controller": row["controller"], "variant": row["variant"], "segment": i,
                        "ok": not own and not other and row["status"] in ("ok", "missed"),
                        "status": row["status"],
                        **{k: seg.get(k) for k in SEGMENT_KEYS},
                        "torque_peak_max": row["torque_peak_max"],
                        "reasons": ", ".join(own + other)})
    return out


def to_csv(result: dict) -> str:
    """compare.csv: one row per controller × variant × segment (``table_rows``)."""
    rows = table_rows(result)
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(rows[0]) if rows else ["controller"])
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()


def to_markdown(result: dict) -> str:
    """The comparison as a Markdown table (errors in mm, times in s)."""
    lines = [f"{result['scenario']}: controllers × plant variants (errors in mm against the true "
             f"target, t_arrive = first time |e| ≤ 1 mm, s)", "",
             "| controller | variant | seg | e0 | e(tf/2) | e(tf) | ė(tf) [mm/s] | hold max | t_arrive "
             "| prescribed | peak τ [N·m] | verdict |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    if result["rows"] and all(r.get("world") for r in result["rows"]):  # no segments: the world's table
        return "\n".join([f"{result['scenario']}: controllers × plant variants"] + world_lines(result)) + "\n"
    for r in table_rows(result):
        seg = result["segments"][r["segment"]] if r["segment"] < len(result["segments"]) else {}
        prescribed = seg.get("start", math.nan) + seg.get("tf", math.nan)
        verdict = "ok" if r["ok"] else (f"MISSED ({r['reasons']})" if r["status"] == "missed"
                                        else f"{r['status']} ({r['reasons']})")
        lines.append(
            f"| {r['controller']} | {r['variant']} | {r['segment']} | {_mm(r['e0_norm'])} | "
            f"{_mm(r['e_half_norm'])} | {_mm(r['e_tf_norm'])} | {_mm(r['edot_tf_norm'])} | "
            f"{_mm(r['e_hold_max_norm'])} | {_s(r['t_arrive'])} | {prescribed:.2f} | "
            f"{_torque(r['torque_peak_max'])} | {verdict} |")
    return "\n".join(lines + world_lines(result)) + "\n"


def world_lines(result: dict) -> list[str]:
    """A second table of the rows' ``world`` values (a world's own row, ``World.compare_row``)."""
    rows = [r for r in result["rows"] if r.get("world")]
    if not rows:
        return []
    keys = list(rows[0]["world"])
    lines = ["", "| controller | variant | " + " | ".join(keys) + " |", "|---|---|" + "---|" * len(keys)]
    for r in rows:
        values = ["–" if r["world"].get(k) is None else str(r["world"][k]) for k in keys]
        lines.append(f"| {r['controller']} | {r['variant']} | " + " | ".join(values) + " |")
    return lines


def figure(result: dict, out_dir: Path) -> None:
    """|e(t)| of every controller on a log axis (tf marked), one column per variant, and the
    largest applied joint torque below."""
    variants = result["variants"]
    fig, axes = plt.subplots(2, len(variants), figsize=(4.6 * len(variants), 6.4), sharex=True,
                             squeeze=False, layout="constrained", height_ratios=[2, 1])
    colors = dict(zip(result["controllers"], plt.rcParams["axes.prop_cycle"].by_key()["color"]))
    for j, variant in enumerate(variants):
        top, bottom = axes[0, j], axes[1, j]
        for row in (r for r in result["rows"] if r["variant"] == variant and "curve" in r):
            c = row["curve"]
            top.semilogy(c["t"], np.maximum(c["e"], 1e-7) * 1e3, color=colors[row["controller"]],
                         label=row["controller"])
            bottom.plot(c["t"], c["tau"], color=colors[row["controller"]])
        for seg in result["segments"]:
            for ax in (top, bottom):
                ax.axvline(seg["start"] + seg["tf"], color="0.5", ls="--", lw=0.8)
        top.axhline(result["criteria"]["e_tf"] * 1e3, color="r", lw=0.8)
        top.set_title(variant)
        top.set_ylabel("|e| [mm]")
        bottom.set_ylabel("max |τ| [N·m]")
        bottom.set_xlabel("t [s]")
    axes[0, 0].legend(fontsize=8, loc="lower left")
    fig.suptitle(f"{result['scenario']}: |e(t)| against the true target (dashed: prescribed "
                 f"times, red: {result['criteria']['e_tf'] * 1e3:g} mm)")
    save(fig, out_dir, "compare")


def write_compare(result: dict, out_dir: Path) -> None:
    """compare.json (without the curves), compare.csv, compare.md and compare.png, staged."""
    from ptint_drake.outputs.folder import staged_output, write_json_atomic  # noqa: PLC0415

    with staged_output(out_dir) as stage:
        (stage / "compare.csv").write_text(to_csv(result))
        (stage / "compare.md").write_text(to_markdown(result))
        if any("curve" in r for r in result["rows"]):  # (a world's own rows have no curves)
            figure(result, stage)
        summary = dict(result, rows=[{k: v for k, v in r.items() if k != "curve"} for r in result["rows"]])
        write_json_atomic(stage / "compare.json", summary)


def summary_line(result: dict) -> str:
    """The one line ``ptint compare`` prints: runs, wall time, how many meet the criteria."""
    rows = result["rows"]
    missed = [f"{r['controller']}/{r['variant']}" for r in rows if not r["ok"]]
    return (f"{len(rows)} runs in {result['wall_time_s']:.0f} s, {len(rows) - len(missed)} meet the "
            f"criteria" + (f"; missed: {', '.join(missed)}" if missed else ""))

