"""The paper report (``ptint paper``): every paper scenario run and written, the
controller comparisons, the TBG family figures and the camera figure, on one page.
"""

from __future__ import annotations

import html
import os
import time
from pathlib import Path

from ptint_drake.outputs.folder import staged_output, write_text_atomic
from ptint_drake.report.run_outputs import frozen_heap, run_and_write
from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.verdict.metrics import segment_reasons
from ptint_drake.views.plots import preload, tbg_family_figure

PAPER_SCENARIOS = {
    "curve_b025_tf15": ("Figs. 6-7", "β = 0.25: intercepts almost linearly; discontinuous velocity, "
                        "large acceleration and jerk peaks"),
    "curve_b050_tf15": ("Figs. 8-9", "β = 0.5: smoother TBG, smaller acceleration and jerk than β = 0.25"),
    "curve_b075_tf15": ("Figs. 10-11", "β = 0.75: smooth TBG, larger path, intercepts at an early point "
                        "of the object's path; acceleration and jerk notably reduced"),
    "curve_b075_tf12": ("Figs. 12-13", "tf = 1.2 s: faster interception, larger α, peaks in "
                        "acceleration and jerk"),
    "curve_b075_tf19": ("Figs. 14-15", "tf = 1.9 s: slower ξ̇, larger path, smooth acceleration and jerk"),
    "assembly": ("Figs. 16-19", "three conveyor objects: velocity error converges at each prescribed "
                 "time (0.5, 2.2, 4.3 s); torques bounded, slightly larger for the short tf"),
}


TBG_FIGURES = {
    "fig2_tbg_beta": ([(1.5, b) for b in (0.25, 0.5, 0.75, 0.9)],
                      "Figs. 2 and 4: TBG and α for β ∈ {0.25, 0.5, 0.75, 0.9}, tf = 1.5 s"),
    "fig3_tbg_tf": ([(tf, 0.7) for tf in (1.2, 1.5, 1.9)],
                    "Figs. 3 and 4: TBG and α for tf ∈ {1.2, 1.5, 1.9} s, β = 0.7 (the paper's value "
                    "for these figures; its scenarios, and ours, use β = 0.75)"),
}


def _fmt_mm(v) -> str:
    return "n/a" if v is None else f"{v * 1e3:.4g}"


COMPARED = ("curve_b075_tf15", "assembly")


def paper_task(kind: str, name: str, *args):
    """One parallel job of ``ptint paper`` (runs in a worker): a paper scenario's run with
    its folder written as ``ptint run`` writes it (args: the paper's folder, svg; returns its
    metrics.json), a TBG family figure, the camera figure, a compare row, a compare
    result's files (args: the result, its folder), or the hold of a paper scenario with the
    paper's own s_d formula after tf (``k_hold = k``)."""
    from ptint_drake.simulation.scenario import scenario_text  # noqa: PLC0415
    from ptint_drake.studies import compare  # noqa: PLC0415

    if kind == "run":
        out_dir, svg = args
        return run_and_write(load_scenario(name), Path(out_dir) / name, svg=svg, workers=1)
    if kind == "tbg":
        settings, title = TBG_FIGURES[name]
        tbg_family_figure(settings, args[0], name, title)
        return None
    if kind == "camera":
        return _camera_figure(args[0])
    if kind == "compare_files":
        return compare.write_compare(*args)
    _, text = scenario_text(name)
    if kind == "compare":
        return compare.compare_run(text, name, *args)
    scenario = load_scenario(name)
    scenario.controller.k_hold = scenario.controller.k
    return [seg["e_hold_max_norm"] for seg in simulate(scenario, check=False).metrics["segments"]]


def task_label(task: tuple) -> str:
    """What one ``paper_task`` job is, for the progress lines."""
    kind, name, *args = task
    if kind == "compare":
        return f"comparison on {name}: {args[0]}, {args[1]}"
    if kind == "hold":
        return f"the paper's hold formula (k_hold = k) on {name}"
    if kind == "tbg":
        return f"TBG figure {name}"
    if kind == "camera":
        return f"camera figure ({name})"
    return f"{kind} {name}"


def _task_reporter(runs: list, tasks: list, progress_factory, notify, every_s: float = 3.0):
    """``run_tasks``' progress callback of ``ptint paper``: a paper scenario's run through
    ``progress_factory`` (its "NAME: 100 %" line), any other job through ``notify`` as
    "[done/total] label", at most one line per ``every_s`` seconds except the last job of
    each kind (so a stage of many short jobs, the comparisons, shows without flooding)."""
    last = {"t": -float("inf")}
    remaining = {}
    for task in tasks[len(runs):]:
        remaining[task[0]] = remaining.get(task[0], 0) + 1

    def report(done, total, index, result):
        if index < len(runs):
            if progress_factory is not None:
                progress_factory(runs[index])(result["duration"], result["duration"])
            return
        kind = tasks[index][0]
        remaining[kind] -= 1
        now = time.monotonic()
        if notify is not None and (now - last["t"] >= every_s or remaining[kind] == 0 or done == total):
            last["t"] = now
            notify(f"[{done}/{total}] {task_label(tasks[index])} done")
    return report


def _parallel_part(out_dir: Path, tbg_stage: Path, svg: bool, workers=None,
                   progress_factory=None, notify=None) -> tuple[dict, dict, dict]:
    """Every simulation of the paper on worker processes, each writing what it shows as
    soon as it is done: the paper scenarios' folders (simulation, figures, replay), the TBG
    figures, the camera figure, the comparisons of ``COMPARED`` and the paper-formula holds,
    the longest first; then the comparisons' files.  Returns (metrics.json of each paper
    scenario, comparisons, holds).  ``notify(message)`` gets a line per stage and, as the
    jobs finish, how many are done (``_task_reporter``)."""
    from ptint_drake.studies import compare  # noqa: PLC0415
    from ptint_drake.studies.runner import run_tasks  # noqa: PLC0415

    controllers, variants = compare.DEFAULT_CONTROLLERS, compare.DEFAULT_VARIANTS
    pairs = compare.pairs(controllers, variants)
    runs = sorted(PAPER_SCENARIOS, key=lambda n: n != "assembly")  # the longest first
    tasks = [("run", name, out_dir, svg) for name in runs] + [("camera", CAMERA_SCENARIO, out_dir / "camera")]
    tasks += [("tbg", stem, tbg_stage) for stem in TBG_FIGURES]
    first = len(tasks)
    tasks += [("compare", name, c, v) for name in COMPARED for c, v in pairs]
    tasks += [("hold", name) for name in PAPER_SCENARIOS]

    say = notify or (lambda message: None)
    say(f"{len(tasks)} jobs on {workers or os.cpu_count() or 1} worker processes: the {len(runs)} paper "
        f"scenarios (each written as `ptint run` writes it), the camera and TBG figures, "
        f"{len(tasks) - first - len(PAPER_SCENARIOS)} comparison runs, {len(PAPER_SCENARIOS)} runs "
        f"of the paper's hold formula")
    report = _task_reporter(runs, tasks, progress_factory, notify)
    t0 = time.perf_counter()
    with frozen_heap():  # every worker is forked from here
        results = run_tasks(paper_task, tasks, workers=workers, progress=report)
    wall = time.perf_counter() - t0
    compared = results[first:]
    comparisons = {name: compare.comparison(load_scenario(name), name, controllers, variants,
                                            compared[k * len(pairs):(k + 1) * len(pairs)], wall)
                   for k, name in enumerate(COMPARED)}
    say(f"writing the comparisons' tables and figures ({', '.join(f'compare_{n}/' for n in COMPARED)})")
    run_tasks(paper_task, [("compare_files", name, result, out_dir / f"compare_{name}")
                           for name, result in comparisons.items()], workers=workers)
    holds = dict(zip(PAPER_SCENARIOS, compared[len(COMPARED) * len(pairs):]))
    return dict(zip(runs, results)), comparisons, holds


def _result_rows(name: str, m: dict, scenario, paper_holds, figs: str, claim: str) -> list[str]:
    rows = []
    for i, seg in enumerate(m["segments"]):
        ok = m["status"] != "failed" and not segment_reasons(seg, scenario.criteria)
        first = i == 0
        rows.append(
            f"<tr><td>{name}{'' if len(m['segments']) == 1 else f' #{i + 1}'}</td>"
            f"<td>{seg['beta']}</td><td>{seg['tf']}</td><td>{_fmt_mm(seg['e0_norm'])}</td>"
            f"<td>{_fmt_mm(seg['e_half_norm'])}</td><td>{_fmt_mm(seg['e_tf_norm'])}</td>"
            f"<td>{_fmt_mm(seg['e_hold_max_norm'])}</td><td>{_fmt_mm(paper_holds[i])}</td>"
            f"<td>{', '.join(f'{v:.2f}' for v in m['torque_peak']) if first else ''}</td>"
            f"<td>{', '.join(f'{v:.2f}' for v in m['torque_peak_after_startup']) if first else ''}</td>"
            f"<td>{'yes' if ok else 'NO'}</td>"
            f"<td>{html.escape(figs + ': ' + claim) if first else ''}</td>"
            f"<td><a href='{name}/replay.html'>replay</a></td></tr>")
    return rows


def _fmt_s(v) -> str:
    return "never" if v is None else f"{v:.2f}"


def _compare_section(name: str, result: dict) -> str:
    from ptint_drake.studies.compare import table_rows  # noqa: PLC0415

    cells = "".join(
        f"<tr><td>{r['controller']}</td><td>{r['variant']}</td><td>{r['segment']}</td>"
        f"<td>{_fmt_mm(r['e_half_norm'])}</td><td>{_fmt_mm(r['e_tf_norm'])}</td>"
        f"<td>{_fmt_mm(r['e_hold_max_norm'])}</td>"
        f"<td>{_fmt_s(r['t_arrive'])}</td>"
        f"<td>{'ok' if r['ok'] else html.escape('MISSED (' + r['reasons'] + ')')}</td></tr>"
        for r in table_rows(result))
    return (f"<h3>{name}</h3><table><tr><th>controller</th><th>variant</th><th>segment</th>"
            f"<th>e(tf/2)</th><th>e(tf)</th><th>hold max</th><th>t_arrive [s]</th><th>verdict</th></tr>"
            f"{cells}</table><p><a href='compare_{name}/compare.png'><img src='compare_{name}/compare.png' "
            f"width='1000'></a></p>")


CAMERA_SCENARIO = "conveyor_pair_camera"


def _camera_figure(out_dir: Path) -> None:
    """Beyond the paper: the estimate a camera-fed run chases, against the truth, around tf."""
    from ptint_drake.simulation.scenario import scenario_text  # noqa: PLC0415
    from ptint_drake.studies.camera import estimate_figure  # noqa: PLC0415

    with staged_output(out_dir) as stage:
        estimate_figure(scenario_text(CAMERA_SCENARIO)[1], CAMERA_SCENARIO, stage)


def summary_line(metrics: dict, index: Path) -> str:
    """``ptint paper``'s last line: how many of the paper's scenarios reproduced, n/N, by
    their verdict (metrics.json ``status`` "ok": every segment meets docs/results.md's
    criteria: |e(tf)| <= 1 mm, not early (|e(tf/2)| >= |e0|/4), |e| <= 3 mm while holding),
    the reasons of those that did not, and the page to open.  ``metrics``: metrics.json of
    each paper scenario, by name."""
    ok = [name for name, m in metrics.items() if m["status"] == "ok"]
    missed = [f"{name}: {m['status']}" + (f" ({'; '.join(m['reasons'])})" if m.get("reasons") else "")
              for name, m in metrics.items() if m["status"] != "ok"]
    return (f"paper: {len(ok)}/{len(metrics)} scenarios reproduced (every segment: |e(tf)| <= 1 mm, "
            f"not early, hold <= 3 mm; docs/results.md)"
            + (f"; not reproduced: {', '.join(missed)}" if missed else "")
            + f"; open {index} in a browser")


def write_paper(out_dir: Path, progress_factory=None, workers=None, svg: bool = False,
                notify=None) -> tuple[Path, dict]:
    """Run every paper scenario and the controller comparisons; write ``out_dir/index.html``
    (``svg``: the run figures as SVG too); returns its path and metrics.json of each paper
    scenario (``summary_line``).  ``progress_factory(name)``: a paper scenario's progress;
    ``notify(message)``: one line per stage and on the other jobs' progress.

    Everything runs on worker processes forked after this one imported matplotlib
    (``figures.preload``): each paper scenario's run writes its folder as ``ptint run``
    does (staged, ``outputs.staged_output``) as soon as it is simulated, beside the other
    simulations (``_parallel_part``)."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    t_start = time.perf_counter()
    (out_dir / "index.html").unlink(missing_ok=True)
    preload(studies=True)  # once, before the workers fork: none imports matplotlib again
    with staged_output(out_dir / "tbg") as stage:
        metrics, comparisons, paper_holds = _parallel_part(out_dir, stage, svg, workers,
                                                           progress_factory, notify)
    if notify is not None:
        notify(f"writing {out_dir / 'index.html'}")
    rows, sections = [], []
    for name, (figs, claim) in PAPER_SCENARIOS.items():
        m = metrics[name]
        rows += _result_rows(name, m, load_scenario(name), paper_holds[name], figs, claim)
        imgs = "".join(f"<a href='{name}/{f}'><img src='{name}/{f}' width='480'></a>"
                       for f in m.get("figures", []))
        sections.append(f"<h2 id='{name}'>{name} ({figs})</h2><p>{html.escape(claim)}. "
                        f"<a href='{name}/replay.html'>Replay</a> · <a href='{name}/metrics.json'>"
                        f"metrics.json</a> · realtime factor {m['sim']['realtime_factor']:.1f}, "
                        f"{m['sim']['steps']} steps</p>{imgs}")
    compared = "".join(_compare_section(name, result) for name, result in comparisons.items())
    page = _page(rows, sections, compared, time.perf_counter() - t_start)
    write_text_atomic(out_dir / "index.html", page)
    return out_dir / "index.html", {name: metrics[name] for name in PAPER_SCENARIOS}


def _page(rows, sections, compared: str, elapsed: float) -> str:
    tbg_imgs = "".join(f"<h3>{html.escape(title)}</h3><img src='tbg/{stem}.png' width='520'>"
                       for stem, (_, title) in TBG_FIGURES.items())
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>ptint_drake: paper reproduction</title>
<style>body{{font-family:sans-serif;margin:2em;max-width:1200px}}table{{border-collapse:collapse}}
td,th{{border:1px solid #bbb;padding:3px 7px;font-size:90%}}img{{margin:4px}}</style></head><body>
<h1>Prescribed-time interception: paper reproduction</h1>
<p>Flores-Campos et al., Robotics 2024, 13(10), 145, reproduced with Drake on the RV-M1 model of
this package (paper gains K = 50, Λ = 5, k = 3, ϵ = δ = 1e-6). Errors in mm. "Intercepted" applies the
prescribed-time property (docs/results.md): |e(tf)| ≤ 1 mm, |e(tf/2)| ≥ |e0|/4, |e| ≤ 3 mm while holding.
"hold max" uses this package's s_d decay after tf (k_hold = 50 1/s); "hold, paper's s_d" the paper's
own formula (k_hold = k = 3 1/s), shown for comparison (the verdict uses the package's).
Peak |τ| after start-up leaves out the first 5 % of each segment's tf (at a segment start the object
moves while the arm rests, so the first step dominates the overall peak).
Generated in {elapsed:.0f} s.</p>
<table><tr><th>scenario</th><th>β</th><th>tf [s]</th><th>e0</th><th>e(tf/2)</th><th>e(tf)</th>
<th>hold max</th><th>hold, paper's s_d</th><th>peak |τ| [N·m]</th><th>peak |τ| after start-up</th>
<th>intercepted</th><th>paper says</th><th></th></tr>
{''.join(rows)}</table>
<h2>Time base generator and α(t)</h2>{tbg_imgs}
<h2>Controllers compared</h2><p>The paper's controller (ptsmc) against a task-space PID (pd), a
first-order sliding mode without the TBG (smc) and a model-based quintic plan tracked by inverse
dynamics of the nominal model, given the target's future (ct_quintic), on the nominal plant and with
every mass × 0.7 and × 1.5 (docs/controllers.md).</p>{compared}
<h2>What a camera sees</h2><p>Beyond the paper: {CAMERA_SCENARIO} with a 30 Hz camera (2 mm noise,
33 ms latency) and the adaptive estimator (auto) in the loop; the controller sees only the
estimate. Top: estimate − truth around each tf; bottom: the gripper against the truth (the metric)
and against the estimate (docs/camera.md; <code>ptint study camera</code> for the
noise × latency × estimator study).</p><p><a href='camera/estimate.png'><img src='camera/estimate.png'
width='900'></a></p>
{''.join(sections)}
</body></html>
"""
