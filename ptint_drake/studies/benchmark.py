"""Speed and accuracy of the bundled scenarios, as JSON (``ptint bench``, ``scripts/benchmark.py``,
``python -m ptint_drake.studies.benchmark``: one command line, ``cli.make_parser``).

For every scenario and configuration it reports the realtime factor (simulated s
/ wall s of the simulation), integrator steps, derivative evaluations, µs per
derivative evaluation, and e(tf) of every segment next to a tight-tolerance
reference run (runge_kutta5, accuracy 1e-10, max step 10 ms) — speed that loses
accuracy does not count.  Configurations: the default (fused, tanh), the five
wired blocks (``blocks``), and the paper's ``sign`` law.
"""

from __future__ import annotations

import platform
import time
from argparse import Namespace
from collections.abc import Callable

from ptint_drake.config.yaml_io import drake_version
from ptint_drake.controllers.slot import uses_analytic_targets
from ptint_drake.simulation import build, make_simulator, simulate
from ptint_drake.simulation.scenario import bundled_scenarios, parse_with_overrides, scenario_text
from ptint_drake.worlds.base import advance_over_stops
from ptint_drake.worlds.registry import world_of

CONFIGS = {
    "default": "",
    "blocks": "controller: {implementation: blocks}",
    "sign": "controller: {switching: sign}",
}
REFERENCE = ("simulator: {integration_scheme: runge_kutta5, accuracy: 1.0e-10, "
             "max_step_size: 0.01}")
# Drake's default step cap.  ``--schemes`` rows use it unless ``--simulator-extra`` sets one, so
# that the bundled scenarios' 2.2 ms cap does not hold the implicit schemes back.
SCHEME_MAX_STEP = "max_step_size: 0.1"
# The bundled scenarios' setting before they capped the step at 2.2 ms (``--pair``'s default B).
BEFORE = f"simulator: {{integration_scheme: runge_kutta3, accuracy: 1.0e-4, {SCHEME_MAX_STEP}}}"


def _run(name: str, overrides: str) -> dict:
    _, text = scenario_text(name)
    scenario = parse_with_overrides(text, overrides, name) if overrides else parse_with_overrides(
        text, "{}", name)
    return simulate(scenario, check=False).metrics


def benchmark(names=None, configs=("default", "blocks", "sign"), reference: bool = True,
              progress=None) -> dict:
    """Time every bundled scenario (or ``names``) in each of ``configs`` (default, blocks,
    sign) against a tight reference run; the JSON ``ptint bench`` prints."""
    names = list(names or bundled_scenarios())
    out = {"machine": {"python": platform.python_version(), "processor": platform.machine(),
                       "cpus": __import__("os").cpu_count()},
           "reference": REFERENCE if reference else None, "scenarios": {}}
    t_start = time.perf_counter()
    for name in names:
        entry = {}
        ref = _run(name, REFERENCE) if reference else None
        if ref is not None:
            entry["reference_e_tf"] = [s["e_tf_norm"] for s in ref["segments"]]
            entry["reference_steps"] = ref["sim"]["steps"]
        for config in configs:
            if progress:
                progress(f"{name} {config}")
            m = _run(name, CONFIGS[config])
            sim = m["sim"]
            row = {
                "realtime_factor": round(sim["realtime_factor"], 3),
                "wall_time_s": round(sim["wall_time_s"], 4),
                "steps": sim["steps"],
                "derivative_evaluations": sim["derivative_evaluations"],
                "us_per_derivative": round(1e6 * sim["wall_time_s"] / sim["derivative_evaluations"], 2),
                "e_tf": [s["e_tf_norm"] for s in m["segments"]],
            }
            if ref is not None:
                row["e_tf_error_vs_reference"] = [
                    abs(a - b) for a, b in zip(row["e_tf"], entry["reference_e_tf"])]
            entry[config] = row
        if "default" in entry and "blocks" in entry:
            entry["speedup_default_vs_blocks"] = round(
                entry["default"]["realtime_factor"] / entry["blocks"]["realtime_factor"], 2)
        out["scenarios"][name] = entry
    out["total_wall_s"] = round(time.perf_counter() - t_start, 1)
    return out


def section_metrics(m: dict) -> dict:
    """The SPEC 5.3 metrics of one run, flat: ``SEGMENT.NAME`` and ``torque_peak.JOINT``."""
    out = {}
    for i, seg in enumerate(m["segments"]):
        for key in ("e0_norm", "e_half_norm", "e_tf_norm", "edot_tf_norm", "e_hold_max_norm"):
            out[f"{i}.{key}"] = seg[key]
    for j, v in enumerate(m["torque_peak"]):
        out[f"torque_peak.{j}"] = v
    return out


def metric_errors(m: dict, ref: dict, rel: float = 0.01, floor: float = 1e-6) -> dict:
    """Per metric |run − reference| / max(rel·|reference|, floor): ≤ 1 is within tolerance
    (1 %, or 1 µm, 1 µm/s, 1 µN·m for tiny values).  ``worst`` names the largest."""
    a, b = section_metrics(m), section_metrics(ref)
    errors = {k: (float("inf") if a.get(k) is None or b[k] is None
                  else abs(a[k] - b[k]) / max(rel * abs(b[k]), floor)) for k in b}
    worst = max(errors, key=errors.get)
    return {"worst": worst, "worst_ratio": errors[worst], "ratios": errors}


def _timed(name: str, overrides: str) -> "tuple[dict, float]":
    t0 = time.perf_counter()
    m = _run(name, overrides)
    return m, time.perf_counter() - t0


def scheme_table(names=None, schemes=("runge_kutta3", "radau3"), accuracies=(1e-3, 1e-4),
                 extra: str = "", progress=None) -> dict:
    """Scheme × accuracy on each scenario: steps, derivative evaluations, realtime factor
    (simulated s / wall s of the whole ``simulate`` call) and the metric errors against
    the reference run.  ``extra`` is more ``simulator`` YAML (e.g. ``max_step_size: 0.02``)."""
    names = list(names or bundled_scenarios())
    out = {"reference": REFERENCE, "tolerance": "max(1 %, 1e-6) per metric", "rows": []}
    for name in names:
        ref = _run(name, REFERENCE)
        for scheme in schemes:
            for accuracy in accuracies:
                more = extra if "max_step_size" in extra else ", ".join(
                    part for part in (SCHEME_MAX_STEP, extra) if part)
                overrides = f"simulator: {{integration_scheme: {scheme}, accuracy: {accuracy}, {more}}}"
                if progress:
                    progress(f"{name} {scheme} {accuracy}")
                row = {"scenario": name, "scheme": scheme, "accuracy": accuracy}
                try:
                    m, wall = _timed(name, overrides)
                except Exception as exc:  # noqa: BLE001 (an integrator failure is a result)
                    row["error"] = " ".join(str(exc).split())[:200]
                    out["rows"].append(row)
                    continue
                err = metric_errors(m, ref)
                row.update(steps=m["sim"]["steps"], derivative_evaluations=m["sim"]["derivative_evaluations"],
                           realtime_factor=round(m["duration"] / wall, 2), status=m["status"],
                           worst_metric=err["worst"], worst_error_ratio=round(err["worst_ratio"], 4),
                           within_tolerance=err["worst_ratio"] <= 1.0)
                out["rows"].append(row)
    return out


def paired(names=None, a: str = "{}", b: str = BEFORE, repeats: int = 5, progress=None) -> dict:
    """Time two settings side by side, interleaved A B A B … in this process, per scenario.

    Each timing is the whole ``simulate`` call (build, simulation, telemetry, metrics).
    ``ratio_b_over_a`` is the median over pairs of wall(B) / wall(A): > 1 means A is faster.
    """
    import statistics

    names = list(names or bundled_scenarios())
    out = {"a": a, "b": b, "repeats": repeats, "scenarios": {}}
    for name in names:
        if progress:
            progress(f"{name} paired")
        _run(name, a), _run(name, b)  # warm-up (imports, first-call costs)
        walls_a, walls_b, ratios = [], [], []
        for _ in range(repeats):
            ma, wa = _timed(name, a)
            mb, wb = _timed(name, b)
            walls_a.append(wa), walls_b.append(wb), ratios.append(wb / wa)
        out["scenarios"][name] = {
            "wall_a_s": round(statistics.median(walls_a), 4),
            "wall_b_s": round(statistics.median(walls_b), 4),
            "ratio_b_over_a": round(statistics.median(ratios), 3),
            "ratio_range": [round(min(ratios), 3), round(max(ratios), 3)],
            "steps": [ma["sim"]["steps"], mb["sim"]["steps"]],
            "derivative_evaluations": [ma["sim"]["derivative_evaluations"],
                                       mb["sim"]["derivative_evaluations"]],
        }
    return out


def _floor_timing(built, scenario, repeats: int) -> dict:
    """µs per derivative evaluation of ``built``'s diagram over the scenario's duration (the
    fastest of ``repeats``), its evaluations, steps and wall time."""
    best, evals, steps = float("inf"), 0, 0
    for _ in range(repeats):
        simulator = make_simulator(built)
        simulator.Initialize()
        t0 = time.perf_counter()
        simulator.AdvanceTo(scenario.duration)
        best = min(best, time.perf_counter() - t0)
        integrator = simulator.get_integrator()
        evals, steps = integrator.get_num_derivative_evaluations(), integrator.get_num_steps_taken()
    return {"us_per_evaluation": round(1e6 * best / evals, 2), "evaluations": int(evals),
            "steps": int(steps), "wall_s": round(best, 4)}


def floors(names=None, repeats: int = 3, progress=None, pairs: int = 5) -> dict:
    """What one derivative evaluation of the closed loop costs, taken apart, per scenario.

    Three diagrams on the scenario's plant (its station: saturation, friction, objects),
    integrator settings and start state, each simulated over the scenario's duration: the
    plant with a C++ constant actuation (Drake's own floor: plant dynamics and the framework),
    with a Python LeafSystem that reads the state and outputs zeros (what any Python controller
    costs before it computes anything), and with the scenario's own controller (no loggers, no
    monitor); all three get ``simulation.build``'s treatment of Python leaves
    (``stateless_derivatives``), so the do-nothing floor is what a Python controller costs in
    the package's own diagrams.  µs per derivative evaluation = the fastest of ``repeats`` wall times / the
    evaluations (the uncontrolled arms take other steps; the cost of an evaluation hardly
    depends on them).  ``needed_for_3x_us``: what an evaluation may cost for the controlled
    run to take a third of its time at the same number of evaluations.  ``kernels_us``: what
    one call of the fused interceptor's row (its compiled kernels and the Python around them,
    ``kernel_cost``) costs on its own.  ``controller_over_python``: controller / do-nothing.
    A scenario with a camera in the loop adds ``python_camera``: the do-nothing controller fed
    by the same cameras, estimators and selectors (their discrete updates, their outputs read
    at every evaluation), and ``controller_over_python_camera``: what the controller adds to
    what any controller fed by the camera pays.  A world whose floor is a replay of its run (no
    ``cpp`` floor but a ``World.floor_diagram(scenario, "replay")``: the pick world) gets
    ``replay_floor`` with ``pairs`` (at least 5) alternated pairs; a world without floor diagrams
    is skipped with a note.
    """
    names = list(names or bundled_scenarios())
    out = {}
    for name in names:
        if progress:
            progress(f"{name} floors")
        _, text = scenario_text(name)
        scenario = parse_with_overrides(text, "{}", name)
        world = world_of(scenario)
        cpp = world.floor_diagram(scenario, "cpp")
        replay = world.floor_diagram(scenario, "replay") if cpp is None else None
        if replay is not None:
            out[name] = replay_floor(replay, max(pairs, 5))
            continue
        if cpp is None:
            out[name] = {"skipped": f"a {world.name} scenario: its world has no floor diagrams"}
            continue
        row = {}
        camera = not uses_analytic_targets(scenario)
        for kind in ("controller", "python", "cpp") + (("python_camera",) if camera else ()):
            row[kind] = _floor_timing(world.floor_diagram(scenario, kind), scenario, repeats)
        row["python_crossing_us"] = round(
            row["python"]["us_per_evaluation"] - row["cpp"]["us_per_evaluation"], 2)
        row["controller_work_us"] = round(
            row["controller"]["us_per_evaluation"] - row["python"]["us_per_evaluation"], 2)
        row["needed_for_3x_us"] = round(row["controller"]["us_per_evaluation"] / 3.0, 2)
        row["controller_over_python"] = round(
            row["controller"]["us_per_evaluation"] / row["python"]["us_per_evaluation"], 3)
        if camera:
            row["controller_over_python_camera"] = round(
                row["controller"]["us_per_evaluation"] / row["python_camera"]["us_per_evaluation"], 3)
        row["kernels_us"] = kernel_cost(scenario)
        out[name] = row
    return out


def _cpu_per_simulated_s(run) -> dict:
    """Process CPU seconds (and wall seconds) of one simulation of ``run`` (a ``WorldRun``) as the
    runner drives it — ``Initialize`` and ``AdvanceTo`` over its stops, ``at_stop`` after each —
    per simulated second; the build and the metrics are not counted."""
    simulator = make_simulator(run)
    run.initialize(simulator.get_mutable_context())
    cpu0, wall0 = time.process_time(), time.perf_counter()
    _, _, simulator, _ = advance_over_stops(simulator, run, run.scenario)  # the runner's own loop
    t = simulator.get_context().get_time()
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    return {"cpu_per_s": cpu / t, "wall_per_s": wall / t,
            "steps": int(simulator.get_integrator().get_num_steps_taken())}


def replay_floor(replay, pairs: int = 5) -> dict:
    """A run beside its floor (``worlds.pick.studies.FloorReplay``: the same station replaying the
    run's arm torques and [q; v] through Drake's C++ PD and its gripper commands, with the run's
    integrator): one recording run, one warm-up of each, then ``pairs`` alternated pairs (run
    first, then floor first, …).  CPU seconds per simulated second of each (median), and
    ``run_over_floor``: the median over pairs of their ratio, with its range."""
    import statistics

    replay.record()
    _cpu_per_simulated_s(replay.run()), _cpu_per_simulated_s(replay.floor())  # warm-up
    runs, floors_, ratios = [], [], []
    for i in range(pairs):
        order = (replay.run, replay.floor) if i % 2 == 0 else (replay.floor, replay.run)
        first, second = (_cpu_per_simulated_s(make()) for make in order)
        run, floor = (first, second) if i % 2 == 0 else (second, first)
        runs.append(run), floors_.append(floor), ratios.append(run["cpu_per_s"] / floor["cpu_per_s"])
    med = lambda rows, key: round(statistics.median(r[key] for r in rows), 4)  # noqa: E731
    return {"pairs": pairs, "integrator": replay.scenario_integrator(),
            "run_cpu_per_simulated_s": med(runs, "cpu_per_s"),
            "floor_cpu_per_simulated_s": med(floors_, "cpu_per_s"),
            "run_wall_per_simulated_s": med(runs, "wall_per_s"),
            "floor_wall_per_simulated_s": med(floors_, "wall_per_s"),
            "run_over_floor": round(statistics.median(ratios), 3),
            "run_over_floor_range": [round(min(ratios), 3), round(max(ratios), 3)],
            "steps": [runs[0]["steps"], floors_[0]["steps"]]}


def kernel_cost(scenario, calls: int = 2000) -> "float | None":
    """µs per call of the fused interceptor's row (``InterceptorLaw.row``: the compiled kernels
    and the Python around them) at the start state, best of 3; None for another controller."""
    built = build(scenario, log=False)
    law = getattr(built.controller.system, "law", None)
    if law is None:
        return None
    context = built.diagram.CreateDefaultContext()
    built.diagram.ExecuteInitializationEvents(context)
    context.SetTime(0.5 * scenario.duration)
    ctx = law.GetMyContextFromRoot(context)
    args = law.row_arguments(ctx)
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        for _ in range(calls):
            law.row(*args)
        best = min(best, time.perf_counter() - t0)
    return round(1e6 * best / calls, 2)


def sweep_benchmark(name: str = "curve_b075_tf15", betas=(0.25, 0.5, 0.75),
                    tfs=(1.2, 1.5, 1.9), workers=(1, 2)) -> dict:
    """Wall time of a 3 × 3 ``ptint sweep`` grid with 1 and 2 worker processes."""
    from ptint_drake.studies.sweep import timed_sweep

    _, text = scenario_text(name)
    walls = {w: timed_sweep(text, name, betas, tfs, w) for w in workers}
    return {"scenario": name, "grid": [list(betas), list(tfs)],
            "wall_s": {str(w): round(s, 3) for w, s in walls.items()},
            "speedup_2_vs_1": round(walls[1] / walls[2], 2) if 1 in walls and 2 in walls else None}


def from_options(args: Namespace, say: "Callable[[str], None] | None" = None) -> dict:
    """The JSON ``ptint bench`` prints for its parsed options (``args``: lists already split and
    checked): ``--floors``, ``--schemes``, ``--pair`` and ``--arms`` (any of them) with the machine's
    description, else every configuration against the reference run (and ``--sweep``)."""
    names = args.scenarios or None
    if not (args.floors or args.schemes or args.pair or args.arms):
        result = benchmark(names, args.configs, not args.no_reference, progress=say)
        if args.sweep:
            result["sweep"] = sweep_benchmark()
        return result
    result = {"machine": {"python": platform.python_version(), "processor": platform.machine(),
                          "cpus": __import__("os").cpu_count(), "drake": drake_version()}}
    if args.floors:
        result["floors"] = floors(names, min(args.repeats, 3), say, pairs=max(args.repeats, 5))
    if args.schemes:
        result["schemes"] = scheme_table(names, args.schemes, args.accuracies, args.simulator_extra, say)
    if args.pair:
        result["paired"] = paired(names, args.pair[0], args.pair[1], args.repeats, say)
    if args.arms:
        from ptint_drake.studies.arm_bench import arms  # noqa: PLC0415

        result["arms"] = arms(args.arms, args.repeats, say)
    return result
