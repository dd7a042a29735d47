"""Intercepting what a camera sees (``ptint study camera``).

|e(tf)| against the *true* target, per segment, on ``conveyor_pair_camera`` over a grid

    noise_std ∈ {0.5, 1, 2, 5} mm × latency ∈ {0, 33, 66} ms ×
    estimator ∈ {none, kalman_cv, kalman_ca}

and ``--seeds`` seeds (measurement.seed = 1 … N): median and 90th percentile over the
runs and the segments (each segment of each run is one value), the median hold and
how many segments arrived early.  ``none`` is the legacy noisy analytic path: the
controller sees x(t − L) + noise (piecewise linear between 30 Hz samples) with the
profile's *true* derivatives, latency compensated with the true profile — an upper
bound of what an estimator can achieve, not a camera model.  The Kalman rows use the
scenario's own filter settings (process noise, 1 s in view before the run), with
``process_noise`` for ``kalman_ca`` from ``CA_PROCESS_NOISE``.

Outputs in DIR: ``camera_study.json`` (every run and the summary), ``camera_study.md``
(the table), ``estimate.png`` (the estimate against the truth around each tf, seed 1,
the scenario's own settings).

Runs go to the studies' runner (``studies.runner.run_tasks``: local worker processes or a
Dask scheduler); each worker builds its own diagram from the scenario text.  Full grid, 10
seeds (360 runs): 156–163 s with 2 workers on a 2-core machine.

The filter's floor (``ptint study camera --filter-floor``, ``filter_floor``): the same
camera and Kalman filter without any arm — the scenario's true objects
(``TargetSource``) feed ``target_view``, the wiring the controllers use (one
``Camera`` + ``TargetKalmanFilter`` per object, primed, and the selector) — so the
error of the filter's continuous output against the truth is what *any* controller
that follows the estimate inherits.  Per process noise q and seed
(measurement.seed = 1 … N): the largest |x̂ − x| of object i's filter over segment
i's hold window [start + tf, next start or duration] (the window of the hold metric),
its RMS there, and the RMS and largest error of the selector's output (what the
interceptor is given) against the active true target over [0, duration].  The
outputs are read at ``FLOOR_SAMPLE_HZ`` (and at the window ends), i.e. 32 times per
30 Hz frame, between the filter's updates, not only at them (curve_camera, seed 1,
q = 0.03: 5.85 / 5.98 / 6.00 mm at 240 / 960 / 3840 Hz).  5 q × 10 seeds: 6 s with
2 workers.  curve_camera (2 mm, 30 Hz, 33 ms), seeds 1–10: median hold max 6.18 mm at
q = 0.03, the smallest of q = 0.003 … 0.3 (7.48, 6.50, 6.18, 6.81, 8.16 mm); the
closed-loop hold median of the same seeds is 6.21 mm.  Outputs:
``filter_floor.json`` (every run and the summary) and ``filter_floor.md`` (the table).
"""

from __future__ import annotations

import copy
import time
from pathlib import Path

import numpy as np

from ptint_drake.figures import plt, save
from ptint_drake.metrics import segment_reasons
from ptint_drake.outputs import staged_output, write_json_atomic
from ptint_drake.studies.runner import run_tasks
from ptint_drake.scenario import (LoadedScenario, Scenario, ScenarioError, parse_scenario, scenario_text,
                                  validate)
from ptint_drake.simulation import simulate


SCENARIO = "conveyor_pair_camera"
NOISES = (0.0005, 0.001, 0.002, 0.005)  # m
LATENCIES = (0.0, 0.033, 0.066)  # s
ESTIMATORS = ("none", "kalman_cv", "kalman_ca")
# kalman_ca on a conveyor: white jerk density (m²/s⁵); the scenario's q is for kalman_cv
CA_PROCESS_NOISE = 1.0e-3
DEFAULT_SEEDS = 10
# filter floor: scenario, process noises q (m²/s⁵ for kalman_ca) and output read rate (Hz)
FLOOR_SCENARIO = "curve_camera"
FLOOR_PROCESS_NOISES = (0.003, 0.01, 0.03, 0.1, 0.3)
FLOOR_SAMPLE_HZ = 960.0


def _with_measurement(text, name: str, measurement: dict, seed: int) -> Scenario:
    """The scenario (YAML ``text`` or a Scenario, copied) with ``measurement`` fields (or dotted scenario
    fields, e.g. ``controller.alpha_hold``) replaced and measurement.seed = ``seed``, validated."""
    scenario = copy.deepcopy(text) if isinstance(text, Scenario) else parse_scenario(text, name)
    for key, value in measurement.items():  # "noise_std" or e.g. "controller.alpha_hold"
        owner, _, field = key.rpartition(".")
        setattr(getattr(scenario, owner) if owner else scenario.measurement, field, value)
    scenario.measurement.seed = seed
    validate(scenario)
    return scenario


def run_case(text: str, name: str, measurement: dict, seed: int) -> dict:
    """One run of the scenario text with ``measurement`` fields (or dotted scenario fields,
    e.g. ``controller.alpha_hold``) replaced and measurement.seed = ``seed``;
    returns per-segment e_tf, hold and verdict reasons (``error`` set if it could not run)."""
    row = {"measurement": dict(measurement), "seed": seed, "error": ""}
    try:
        scenario = _with_measurement(text, name, measurement, seed)
        result = simulate(scenario, check=False)
    except (ScenarioError, RuntimeError) as exc:
        row["error"] = " ".join(str(exc).split())[:200]
        return row
    m = result.metrics
    row["status"] = m["status"]
    row["segments"] = [{"e0": s["e0_norm"], "e_half": s["e_half_norm"], "e_tf": s["e_tf_norm"],
                        "hold": s["e_hold_max_norm"],
                        "reasons": segment_reasons(s, scenario.criteria)} for s in m["segments"]]
    row["wall_s"] = m["sim"]["wall_time_s"]
    return row


def run_many(cases: list, workers: int = 2, dask=None, progress=None) -> list:
    """``cases`` = [(text, name, measurement, seed), …] → rows in the same order."""
    return run_tasks(run_case, cases, workers=workers, dask=dask, progress=progress)


def summarize(rows: list) -> dict:
    """Median / p90 of |e(tf)| over every segment of every run, median hold, early count."""
    done = [r for r in rows if not r.get("error")]
    e_tf = [s["e_tf"] for r in done for s in r["segments"]]
    hold = [s["hold"] for r in done for s in r["segments"]]
    out = {"runs": len(rows), "errors": len(rows) - len(done),
           "early": sum("early" in s["reasons"] for r in done for s in r["segments"])}
    if e_tf:
        out.update({"e_tf_median": float(np.median(e_tf)), "e_tf_p90": float(np.percentile(e_tf, 90)),
                    "hold_median": float(np.median(hold)), "hold_p90": float(np.percentile(hold, 90))})
        per_segment = list(zip(*[[s["e_tf"] for s in r["segments"]] for r in done]))
        out["e_tf_median_per_segment"] = [float(np.median(v)) for v in per_segment]
    return out


def grid_cases(text: str, name: str, seeds: int, noises=NOISES, latencies=LATENCIES,
               estimators=ESTIMATORS) -> list:
    cases = []
    for estimator in estimators:
        for noise in noises:
            for latency in latencies:
                m = {"estimator": estimator, "noise_std": noise, "latency": latency,
                     "compensate_latency": True}
                if estimator == "kalman_ca":
                    m["process_noise"] = CA_PROCESS_NOISE
                cases += [(text, name, m, seed) for seed in range(1, seeds + 1)]
    return cases


def markdown(summary_rows: list, seeds: int, scenario: str) -> str:
    lines = [f"# Camera study: {scenario}, {seeds} seeds",
             "",
             "|e(tf)| against the true target over every segment of every seed (mm); hold = the "
             "largest |e| after tf (mm, median); early = segments that arrived early.",
             "",
             "| estimator | noise (mm) | latency (ms) | e(tf) median | e(tf) p90 | hold median | early |",
             "|---|---:|---:|---:|---:|---:|---:|"]
    for row in summary_rows:
        s = row["summary"]
        if "e_tf_median" not in s:
            lines.append(f"| {row['estimator']} | {row['noise_std'] * 1e3:g} | {row['latency'] * 1e3:g} "
                         f"| error | | | |")
            continue
        lines.append(f"| {row['estimator']} | {row['noise_std'] * 1e3:g} | {row['latency'] * 1e3:g} | "
                     f"{s['e_tf_median'] * 1e3:.2f} | {s['e_tf_p90'] * 1e3:.2f} | "
                     f"{s['hold_median'] * 1e3:.2f} | {s['early']} |")
    return "\n".join(lines) + "\n"


def estimate_figure(text: str, name: str, out_dir: Path, window: float = 0.3) -> None:
    """The controller's target (the filter's estimate) and the gripper against the true
    object around each segment's tf (seed 1, the scenario's own settings)."""
    scenario = parse_scenario(text, name)
    result = simulate(scenario, check=False)
    s = result.series
    t = s["t"]
    segments = scenario.schedule().segments
    fig, axes = plt.subplots(2, len(segments), figsize=(5.5 * len(segments), 6.5), squeeze=False)
    for i, seg in enumerate(segments):
        hold_end = scenario.schedule().hold_end(i, scenario.duration)
        mask = (t >= seg.end - window) & (t <= min(seg.end + window, hold_end)) & \
            ~((t >= hold_end) & (i + 1 < len(segments)))  # not the next object's first sample
        truth = s["objects"][mask, 3 * i:3 * i + 3]
        est_err = (s["x_r"][mask] - truth) * 1e3
        arm_err = (s["x"][mask] - truth) * 1e3
        ax = axes[0, i]
        for k, axis in enumerate("xyz"):
            ax.plot(t[mask], est_err[:, k], label=f"estimate − truth, {axis}")
        ax.plot(t[mask], np.linalg.norm(est_err, axis=1), "k", lw=1.5, label="|estimate − truth|")
        ax.axvline(seg.end, color="gray", ls="--")
        ax.set_ylabel("mm")
        ax.set_title(f"segment {i}: the controller's target (Kalman) around tf = {seg.end:g} s", fontsize=9)
        ax.legend(fontsize=7)
        ax = axes[1, i]
        ax.plot(t[mask], np.linalg.norm(arm_err, axis=1), "C3", label="|gripper − truth| (the metric)")
        ax.plot(t[mask], np.linalg.norm(s["x"][mask] - s["x_r"][mask], axis=1) * 1e3, "C0",
                label="|gripper − estimate| (what the controller drives to 0)")
        ax.axvline(seg.end, color="gray", ls="--")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("mm")
        ax.legend(fontsize=7)
    m = scenario.measurement
    fig.suptitle(f"{name}: {m.estimator}, {m.rate_hz:g} Hz, noise {m.noise_std * 1e3:g} mm, "
                 f"latency {m.latency * 1e3:g} ms, q = {m.process_noise:g}, seed {m.seed}")
    save(fig, out_dir, "estimate")


def run_study(seeds: int = DEFAULT_SEEDS, workers: int = 2, out: Path = Path("out/study_camera"),
              scenario: str = SCENARIO, progress=None) -> dict:
    name, text = scenario_text(scenario)
    base = parse_scenario(text, name)  # validates before any worker starts
    t0 = time.perf_counter()
    cases = grid_cases(text, name, seeds)
    rows = run_many(cases, workers, progress=progress)
    table = []
    for i in range(0, len(rows), seeds):
        m = cases[i][2]
        table.append({**{k: m[k] for k in ("estimator", "noise_std", "latency")},
                      "process_noise": m.get("process_noise", base.measurement.process_noise)
                      if m["estimator"] != "none" else None,
                      "summary": summarize(rows[i:i + seeds])})
    wall = time.perf_counter() - t0
    result = {"scenario": name, "seeds": seeds, "workers": workers, "wall_time_s": wall,
              "base_measurement": copy.deepcopy(vars(base.measurement)),
              "table": table, "runs": rows}
    with staged_output(out) as stage:
        estimate_figure(text, name, stage)
        footer = f"\n{len(rows)} runs, {wall:.0f} s with {workers} workers.\n"
        (stage / "camera_study.md").write_text(markdown(table, seeds, name) + footer)
        write_json_atomic(stage / "camera_study.json", result)
    return result


# --------------------------------------------------------------------------- the filter's floor

def check_floor_scenario(scenario: Scenario) -> None:
    """ScenarioError naming ``measurement.estimator`` unless a Kalman filter is configured."""
    if scenario.measurement.estimator not in ("kalman_cv", "kalman_ca"):
        raise ScenarioError(f"measurement.estimator: the filter floor needs kalman_cv or kalman_ca, "
                            f"{scenario.name} has {scenario.measurement.estimator!r}")


def floor_times(scenario: Scenario, sample_hz: float) -> np.ndarray:
    """0, 1/sample_hz, … ≤ duration, plus every segment's start + tf and hold end."""
    duration = scenario.duration
    schedule = scenario.schedule()
    grid = np.arange(0.0, duration + 0.5 / sample_hz, 1.0 / sample_hz)
    grid = grid[grid <= duration]
    ends = [t for i, seg in enumerate(schedule.segments)
            for t in (seg.end, schedule.hold_end(i, duration)) if t <= duration]
    return np.unique(np.concatenate([grid, ends, [duration]]))


def floor_case(text: str, name: str, measurement: dict, seed: int,
               sample_hz: float = FLOOR_SAMPLE_HZ) -> dict:
    """One run of the scenario's true objects → camera → Kalman filter (no arm, no controller)
    with ``measurement`` fields replaced and measurement.seed = ``seed``.

    Measured at ``floor_times`` (the simulator advanced to each, the outputs read there:
    at an update instant, the prediction before the update): per segment i, the largest
    and the RMS |x̂_i − x_i| over [start + tf, hold end] (x̂_i: filter i's ``target``
    position, x_i: object i, as the hold metric pairs them); over the run, the RMS and
    the largest |x̂ − x| of the selector's output against the active true target.
    ``error`` is set if the case could not run."""
    from pydrake.systems.analysis import Simulator  # noqa: PLC0415
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.controllers import target_view  # noqa: PLC0415
    from ptint_drake.systems.targets import TargetSource  # noqa: PLC0415

    row = {"measurement": dict(measurement), "seed": seed, "error": ""}
    t0 = time.perf_counter()
    try:
        scenario = _with_measurement(text, name, measurement, seed)
        check_floor_scenario(scenario)
        schedule = scenario.schedule()
        builder = DiagramBuilder()
        truth = builder.AddNamedSystem("objects", TargetSource(schedule, scenario.targets()))
        view = target_view(builder, truth, scenario)  # the controllers' camera + filter wiring
        builder.ExportOutput(view, "estimate")
        diagram = builder.Build()
        filters = [diagram.GetSubsystemByName(f"target_filter_{i}") for i in range(len(schedule))]
        simulator = Simulator(diagram)
        context = simulator.get_mutable_context()
        truth_context = truth.GetMyContextFromRoot(context)
        filter_contexts = [kf.GetMyContextFromRoot(context) for kf in filters]
        estimate_port = diagram.GetOutputPort("estimate")
        simulator.Initialize()
        times = floor_times(scenario, sample_hz)
        n = len(filters)
        objects = np.zeros((len(times), 3 * n))
        per_filter = np.zeros((len(times), 3 * n))
        active_truth = np.zeros((len(times), 3))
        active_estimate = np.zeros((len(times), 3))
        for k, t in enumerate(times):
            if t > context.get_time():
                simulator.AdvanceTo(t)
            objects[k] = truth.get_objects_output_port().Eval(truth_context)
            active_truth[k] = truth.get_x_r_output_port().Eval(truth_context)
            active_estimate[k] = estimate_port.Eval(context)[0:3]
            for i, (kf, kf_context) in enumerate(zip(filters, filter_contexts)):
                per_filter[k, 3 * i:3 * i + 3] = kf.get_target_output_port().Eval(kf_context)[0:3]
    except (ScenarioError, RuntimeError, ValueError) as exc:
        row["error"] = " ".join(str(exc).split())[:200]
        return row
    segments = []
    for i, seg in enumerate(schedule.segments):
        hold = (times >= seg.end) & (times <= schedule.hold_end(i, scenario.duration))
        e = np.linalg.norm(per_filter[hold, 3 * i:3 * i + 3] - objects[hold, 3 * i:3 * i + 3], axis=1)
        segments.append({"hold_from": seg.end, "hold_to": schedule.hold_end(i, scenario.duration),
                         "samples": int(hold.sum()),
                         "hold_max": float(e.max()) if len(e) else None,
                         "hold_rms": float(np.sqrt(np.mean(e * e))) if len(e) else None})
    e_run = np.linalg.norm(active_estimate - active_truth, axis=1)
    row.update(segments=segments, run_rms=float(np.sqrt(np.mean(e_run * e_run))),
               run_max=float(e_run.max()), samples=len(times), wall_s=time.perf_counter() - t0)
    return row


def summarize_floor(rows: list) -> dict:
    """Median / p90 of the hold-window maxima over every segment of every seed (each one
    value), median hold RMS, median and p90 of the whole-run RMS, median run maximum."""
    done = [r for r in rows if not r.get("error")]
    out = {"runs": len(rows), "errors": len(rows) - len(done)}
    hold = [s["hold_max"] for r in done for s in r["segments"] if s["hold_max"] is not None]
    if hold:
        rms = [s["hold_rms"] for r in done for s in r["segments"] if s["hold_rms"] is not None]
        run_rms = [r["run_rms"] for r in done]
        out.update({"hold_max_median": float(np.median(hold)),
                    "hold_max_p90": float(np.percentile(hold, 90)),
                    "hold_max_worst": float(np.max(hold)),
                    "hold_rms_median": float(np.median(rms)),
                    "run_rms_median": float(np.median(run_rms)),
                    "run_rms_p90": float(np.percentile(run_rms, 90)),
                    "run_max_median": float(np.median([r["run_max"] for r in done]))})
        per_segment = list(zip(*[[s["hold_max"] for s in r["segments"]] for r in done]))
        out["hold_max_median_per_segment"] = [float(np.median(v)) for v in per_segment]
    return out


def filter_floor(loaded: LoadedScenario, process_noises=FLOOR_PROCESS_NOISES, seeds: int = DEFAULT_SEEDS,
                 measurement: dict | None = None, sample_hz: float = FLOOR_SAMPLE_HZ,
                 workers: int | None = 2, dask=None, progress=None) -> dict:
    """The filter-only error floor of the camera scenario ``loaded`` (module docstring): for each
    process noise q in ``process_noises`` and measurement.seed = 1 … ``seeds``, one
    ``floor_case`` with ``measurement`` fields (e.g. ``{"noise_std": 0.001}``) also
    replaced; returns the settings, a ``table`` (per q: ``summarize_floor``), every run
    (``runs``, ordered q-major) and ``best`` (the q with the smallest median hold max).
    ScenarioError (naming the field) on a bad scenario, q ≤ 0, seeds < 1 or sample_hz ≤ 0."""
    qs = [float(q) for q in process_noises]
    if not qs:
        raise ScenarioError("process_noise: no values given")
    for q in qs:
        if not (np.isfinite(q) and q > 0.0):
            raise ScenarioError(f"process_noise: every value must be > 0, got {q:g}")
    if isinstance(seeds, bool) or not isinstance(seeds, int) or seeds < 1:
        raise ScenarioError(f"seeds: must be an integer >= 1, got {seeds!r}")
    if not (np.isfinite(sample_hz) and sample_hz > 0.0):
        raise ScenarioError(f"sample_hz: must be > 0, got {sample_hz}")
    overrides = dict(measurement or {})
    base = _with_measurement(loaded.scenario, loaded.name, overrides, 1)  # before any worker starts
    check_floor_scenario(base)
    t0 = time.perf_counter()
    cases = [(loaded.text, loaded.name, {**overrides, "process_noise": q}, seed, sample_hz)
             for q in qs for seed in range(1, seeds + 1)]
    rows = run_tasks(floor_case, cases, workers=workers, dask=dask, progress=progress)
    table = [{"process_noise": q, "summary": summarize_floor(rows[j * seeds:(j + 1) * seeds])}
             for j, q in enumerate(qs)]
    ranked = [row for row in table if "hold_max_median" in row["summary"]]
    best = min(ranked, key=lambda row: row["summary"]["hold_max_median"]) if ranked else None
    m = base.measurement
    return {"scenario": loaded.name, "seeds": seeds, "sample_hz": sample_hz, "workers": workers,
            "wall_time_s": time.perf_counter() - t0,
            "measurement_overrides": overrides,
            "measurement": {k: v for k, v in copy.deepcopy(vars(m)).items()
                            if k not in ("seed", "process_noise")},
            "segments": [{"start": s.start, "tf": s.tf,
                          "hold_end": base.schedule().hold_end(i, base.duration)}
                         for i, s in enumerate(base.schedule().segments)],
            "duration": base.duration,
            "table": table, "best": best, "runs": rows}


def floor_markdown(result: dict) -> str:
    """The table of ``filter_floor``'s result (mm)."""
    m = result["measurement"]
    windows = ", ".join(f"[{s['start'] + s['tf']:g}, {s['hold_end']:g}] s" for s in result["segments"])
    lines = [f"# Filter floor: {result['scenario']}, {result['seeds']} seeds",
             "",
             f"Camera + Kalman filter only (no arm): {m['estimator']}, {m['rate_hz']:g} Hz, noise "
             f"{m['noise_std'] * 1e3:g} mm, latency {m['latency'] * 1e3:g} ms"
             f"{' (compensated)' if m['compensate_latency'] else ''}"
             + (f"; overrides {result['measurement_overrides']}" if result["measurement_overrides"] else "")
             + f". |filter output − true object| read at {result['sample_hz']:g} Hz. hold max = the largest "
             f"error over the hold window ({windows}), median and p90 over every segment of every seed; "
             "hold RMS = its RMS there (median); run RMS / run max = the selector's output against the "
             f"active true object over [0, {result['duration']:g}] s (median). All in mm.",
             "",
             "| q | hold max median | hold max p90 | hold max worst | hold RMS median | run RMS median | "
             "run max median | errors |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in result["table"]:
        s = row["summary"]
        if "hold_max_median" not in s:
            lines.append(f"| {row['process_noise']:g} | error | | | | | | {s['errors']} |")
            continue
        lines.append(f"| {row['process_noise']:g} | {s['hold_max_median'] * 1e3:.2f} | "
                     f"{s['hold_max_p90'] * 1e3:.2f} | {s['hold_max_worst'] * 1e3:.2f} | "
                     f"{s['hold_rms_median'] * 1e3:.2f} | {s['run_rms_median'] * 1e3:.2f} | "
                     f"{s['run_max_median'] * 1e3:.2f} | {s['errors']} |")
    return "\n".join(lines) + "\n"


def floor_summary_line(result: dict) -> str:
    """One line: the best q and its median / p90 hold max."""
    runs = sum(row["summary"]["runs"] for row in result["table"])
    errors = sum(row["summary"]["errors"] for row in result["table"])
    head = f"{result['scenario']} filter floor, {runs} runs ({errors} could not run)"
    best = result["best"]
    if best is None:
        return head + " in {:.0f} s: no run completed".format(result["wall_time_s"])
    s = best["summary"]
    return (f"{head} in {result['wall_time_s']:.0f} s: best q = {best['process_noise']:g}, hold max "
            f"median {s['hold_max_median'] * 1e3:.2f} mm, p90 {s['hold_max_p90'] * 1e3:.2f} mm")


def write_filter_floor(result: dict, out: Path) -> None:
    """``filter_floor.md`` and ``filter_floor.json`` in ``out``, staged (all or nothing)."""
    with staged_output(out) as stage:
        (stage / "filter_floor.md").write_text(
            floor_markdown(result) + f"\n{sum(r['summary']['runs'] for r in result['table'])} runs, "
            f"{result['wall_time_s']:.0f} s with {result['workers']} workers.\n")
        write_json_atomic(stage / "filter_floor.json", result)
