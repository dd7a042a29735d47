"""The filter's floor (``ptint study camera --filter-floor``, ``filter_floor``).

The camera and estimator of a camera scenario without any arm: the scenario's
true objects (``TargetSource``) feed ``kalman.AddCameraEstimators`` as the controllers'
target view does (one ``Camera`` + estimator per object, primed, and the
selector), so the error of the filter's continuous output against the truth is what *any* controller
that follows the estimate inherits.  Rows: ``auto`` (the adaptive estimator, nothing to
tune), then a hand-set filter per process noise q: the scenario's (or the overrides')
``kalman_cv`` / ``kalman_ca``, else ``FLOOR_MODEL``.  Per row and seed
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

from ptint_drake.outputs.folder import staged_output, write_json_atomic
from ptint_drake.simulation.scenario import LoadedScenario, Scenario, ScenarioError
from ptint_drake.studies.camera import DEFAULT_SEEDS, with_measurement
from ptint_drake.studies.runner import run_tasks
from ptint_drake.worlds.base import new_simulator
from ptint_drake.worlds.registry import schedule_of, world_of

# scenario, process noises q (m²/s⁵ for kalman_ca) and output read rate (Hz)
FLOOR_SCENARIO = "curve_camera"
FLOOR_PROCESS_NOISES = (0.003, 0.01, 0.03, 0.1, 0.3)
FLOOR_SAMPLE_HZ = 960.0
FLOOR_MODEL = "kalman_ca"  # the hand-set filter of the q rows


def check_floor_scenario(scenario: Scenario) -> None:
    """ScenarioError naming ``measurement`` unless the scenario has a camera and an estimator."""
    if scenario.measurement is None or scenario.measurement.estimator == "none":
        raise ScenarioError(f"measurement: the filter floor needs a camera scenario, {scenario.name} "
                            "has no camera")


def floor_times(scenario: Scenario, sample_hz: float) -> np.ndarray:
    """0, 1/sample_hz, … ≤ duration, plus every segment's start + tf and hold end."""
    duration = scenario.duration
    schedule = schedule_of(scenario)
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
    row = {"measurement": dict(measurement), "seed": seed, "error": ""}
    t0 = time.perf_counter()
    try:
        scenario = with_measurement(text, name, measurement, seed)
        check_floor_scenario(scenario)
        times = floor_times(scenario, sample_hz)
        read = _read_filters(scenario, times)
    except (ScenarioError, RuntimeError, ValueError) as exc:
        row["error"] = " ".join(str(exc).split())[:200]
        return row
    schedule = schedule_of(scenario)
    segments = []
    for i, seg in enumerate(schedule.segments):
        hold = (times >= seg.end) & (times <= schedule.hold_end(i, scenario.duration))
        e = np.linalg.norm(read["filters"][hold, 3 * i:3 * i + 3] - read["objects"][hold, 3 * i:3 * i + 3],
                           axis=1)
        segments.append({"hold_from": seg.end, "hold_to": schedule.hold_end(i, scenario.duration),
                         "samples": int(hold.sum()),
                         "hold_max": float(e.max()) if len(e) else None,
                         "hold_rms": float(np.sqrt(np.mean(e * e))) if len(e) else None})
    e_run = np.linalg.norm(read["estimate"] - read["truth"], axis=1)
    row.update(segments=segments, run_rms=float(np.sqrt(np.mean(e_run * e_run))),
               run_max=float(e_run.max()), samples=len(times), wall_s=time.perf_counter() - t0)
    return row


def _read_filters(scenario: Scenario, times: np.ndarray) -> dict:
    """Simulate the true objects → cameras → filters → selector and read, at each of
    ``times``: ``objects`` (every true position), ``filters`` (every filter's position),
    ``truth`` (the active true target) and ``estimate`` (the selector's output)."""
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.systems.estimation.kalman import AddCameraEstimators  # noqa: PLC0415
    from ptint_drake.systems.task.targets import TargetSource  # noqa: PLC0415

    builder = DiagramBuilder()
    truth = builder.AddNamedSystem("objects", TargetSource(schedule_of(scenario),
                                                         world_of(scenario).objects(scenario)))
    estimators = AddCameraEstimators(builder, objects_port=truth.get_objects_output_port(),
                                     schedule=schedule_of(scenario), config=scenario.measurement,
                                     histories=world_of(scenario).objects(scenario))  # in view before t = 0
    diagram = builder.Build()
    simulator = new_simulator(diagram)
    context = simulator.get_mutable_context()
    truth_context = truth.GetMyContextFromRoot(context)
    filters = [(kf, kf.GetMyContextFromRoot(context)) for kf in estimators.filters]
    selector_context = estimators.selector.GetMyContextFromRoot(context)
    n = len(filters)
    read = {"objects": np.zeros((len(times), 3 * n)), "filters": np.zeros((len(times), 3 * n)),
            "truth": np.zeros((len(times), 3)), "estimate": np.zeros((len(times), 3))}
    simulator.Initialize()
    for k, t in enumerate(times):
        if t > context.get_time():
            simulator.AdvanceTo(t)
        read["objects"][k] = truth.get_objects_output_port().Eval(truth_context)
        read["truth"][k] = truth.get_x_r_output_port().Eval(truth_context)
        read["estimate"][k] = estimators.target_port.Eval(selector_context)[0:3]
        for i, (kf, kf_context) in enumerate(filters):
            read["filters"][k, 3 * i:3 * i + 3] = kf.get_target_output_port().Eval(kf_context)[0:3]
    return read


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
    replaced; returns the settings, a ``table`` (``auto``, then per q: ``summarize_floor``),
    every run (``runs``, ordered row-major) and ``best`` (the hand-set q with the smallest
    median hold max).
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
    check_floor_scenario(loaded.scenario)  # a camera of its own, before any override
    overrides = dict(measurement or {})
    base = with_measurement(loaded.scenario, loaded.name, overrides, 1)  # before any worker starts
    check_floor_scenario(base)
    hand = overrides.pop("estimator", base.measurement.estimator)
    hand = hand if hand in ("kalman_cv", "kalman_ca") else FLOOR_MODEL
    overrides.pop("process_noise", None)
    settings = [{"estimator": "auto", "process_noise": None}] + [
        {"estimator": hand, "process_noise": q} for q in qs]
    t0 = time.perf_counter()
    cases = [(loaded.text, loaded.name, {**overrides, **setting}, seed, sample_hz)
             for setting in settings for seed in range(1, seeds + 1)]
    rows = run_tasks(floor_case, cases, workers=workers, dask=dask, progress=progress,
                     folders=loaded.folders)
    table = [{**setting, "summary": summarize_floor(rows[j * seeds:(j + 1) * seeds])}
             for j, setting in enumerate(settings)]
    ranked = [row for row in table[1:] if "hold_max_median" in row["summary"]]
    best = min(ranked, key=lambda row: row["summary"]["hold_max_median"]) if ranked else None
    m = base.measurement
    return {"scenario": loaded.name, "seeds": seeds, "sample_hz": sample_hz, "workers": workers,
            "wall_time_s": time.perf_counter() - t0,
            "measurement_overrides": overrides,
            "measurement": {k: v for k, v in copy.deepcopy(vars(m)).items()
                            if k not in ("seed", "process_noise", "estimator")},
            "segments": [{"start": s.start, "tf": s.tf,
                          "hold_end": schedule_of(base).hold_end(i, base.duration)}
                         for i, s in enumerate(schedule_of(base).segments)],
            "duration": base.duration,
            "table": table, "best": best, "runs": rows}


def floor_markdown(result: dict) -> str:
    """The table of ``filter_floor``'s result (mm)."""
    m = result["measurement"]
    windows = ", ".join(f"[{s['start'] + s['tf']:g}, {s['hold_end']:g}] s" for s in result["segments"])
    lines = [f"# Filter floor: {result['scenario']}, {result['seeds']} seeds",
             "",
             f"Camera + estimator only (no arm): {m['rate_hz']:g} Hz, noise "
             f"{m['noise_std'] * 1e3:g} mm, latency {m['latency'] * 1e3:g} ms"
             f"{' (compensated)' if m['compensate_latency'] else ''}"
             + (f"; overrides {result['measurement_overrides']}" if result["measurement_overrides"] else "")
             + f". |filter output − true object| read at {result['sample_hz']:g} Hz. hold max = the largest "
             f"error over the hold window ({windows}), median and p90 over every segment of every seed; "
             "hold RMS = its RMS there (median); run RMS / run max = the selector's output against the "
             f"active true object over [0, {result['duration']:g}] s (median). All in mm.",
             "",
             "| estimator | q | hold max median | hold max p90 | hold max worst | hold RMS median | "
             "run RMS median | run max median | errors |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for row in result["table"]:
        s = row["summary"]
        q = "" if row["process_noise"] is None else f"{row['process_noise']:g}"
        if "hold_max_median" not in s:
            lines.append(f"| {row['estimator']} | {q} | error | | | | | | {s['errors']} |")
            continue
        lines.append(f"| {row['estimator']} | {q} | {s['hold_max_median'] * 1e3:.2f} | "
                     f"{s['hold_max_p90'] * 1e3:.2f} | {s['hold_max_worst'] * 1e3:.2f} | "
                     f"{s['hold_rms_median'] * 1e3:.2f} | {s['run_rms_median'] * 1e3:.2f} | "
                     f"{s['run_max_median'] * 1e3:.2f} | {s['errors']} |")
    return "\n".join(lines) + "\n"


def floor_summary_line(result: dict) -> str:
    """One line: auto's and the best q's median / p90 hold max."""
    runs = sum(row["summary"]["runs"] for row in result["table"])
    errors = sum(row["summary"]["errors"] for row in result["table"])
    head = f"{result['scenario']} filter floor, {runs} runs ({errors} could not run)"
    best, auto = result["best"], result["table"][0]["summary"]
    if best is None or "hold_max_median" not in auto:
        return head + " in {:.0f} s: no run completed".format(result["wall_time_s"])
    s = best["summary"]
    return (f"{head} in {result['wall_time_s']:.0f} s: auto hold max median "
            f"{auto['hold_max_median'] * 1e3:.2f} mm, p90 {auto['hold_max_p90'] * 1e3:.2f} mm; best "
            f"{best['estimator']} q = {best['process_noise']:g}: {s['hold_max_median'] * 1e3:.2f} mm, "
            f"p90 {s['hold_max_p90'] * 1e3:.2f} mm")


def write_filter_floor(result: dict, out: Path) -> None:
    """``filter_floor.md`` and ``filter_floor.json`` in ``out``, staged (all or nothing)."""
    with staged_output(out) as stage:
        (stage / "filter_floor.md").write_text(
            floor_markdown(result) + f"\n{sum(r['summary']['runs'] for r in result['table'])} runs, "
            f"{result['wall_time_s']:.0f} s with {result['workers']} workers.\n")
        write_json_atomic(stage / "filter_floor.json", result)
