"""The one runner: a scenario's world builds the diagram; this module owns the ``Simulator``, the
``AdvanceTo`` loop over the world's exact stops, the watchdog, progress, the verdict and the
result, for every world alike (``worlds.base`` has the protocol).

``simulate`` creates the simulator with the world's integrator settings, lets the world set
its start (``initialize``), installs the world's monitor (the divergence watchdog) and stops at
each of the world's ``stops()`` exactly.  An integrator failure ends the run as ``failed``; so
does an exception raised inside a user's controller (a plugin), while the package's own are bugs
and propagate.  The metrics' common tail — verdict, reasons, criteria, warnings, controller and
the ``sim`` block (``realtime_factor`` end to end: simulation, series, metrics;
``simulation_realtime_factor`` the simulation alone) — is written here once.
"""

from __future__ import annotations

import dataclasses
import time
from typing import Callable, Optional

from pydrake.systems.analysis import Simulator

from ptint_drake.config.schema import Scenario
from ptint_drake.controllers.ptsmc.jit_notice import compile_notice
from ptint_drake.worlds.base import Progress, RunResult, WorldRun, advance_over_stops, new_simulator
from ptint_drake.worlds.registry import world_of

__all__ = ["RunResult", "make_simulator", "simulate"]


def make_simulator(run: WorldRun) -> Simulator:
    """A simulator of the run's diagram with the world's integrator settings, from the diagram's
    default context (the station's defaults are the scenario's start)."""
    return new_simulator(run.diagram, config=run.simulator_config)


def simulate(scenario: Scenario, check: bool = True, progress: Progress = None,
             warn: Optional[Callable[[str], None]] = None) -> RunResult:
    """Run a scenario in its world; returns its metrics (with the verdict) and logged series.

    ``progress(t, duration, steps)`` is called while it runs; ``warn(message)`` for each warning
    known before the simulation starts, as soon as it is known; with ``progress``, one line on
    stderr while numba compiles the controller's equations (an empty JIT cache,
    ``controllers.ptsmc.jit_notice``).  A run stopped by the watchdog or an integrator failure returns
    normally with ``status == "failed"``.
    """
    world = world_of(scenario)
    with compile_notice(enabled=progress is not None):  # the kernels load (or compile) here
        run = world.prepare(scenario)
        warnings = run.pre_run_warnings() if check else []
    for message in warnings if warn is not None else ():
        warn(message)
    n_before = len(warnings)
    t_start = time.perf_counter()  # the realtime factor counts simulation, series, metrics
    simulator = make_simulator(run)
    run.initialize(simulator.get_mutable_context())
    monitor = run.monitor(progress)
    if monitor is not None:
        simulator.set_monitor(monitor)
    failure, wall, simulator, steps_before = advance_over_stops(simulator, run, scenario, progress, monitor)
    context, integrator = simulator.get_context(), simulator.get_integrator()
    if progress is not None:
        progress(context.get_time(), scenario.duration, steps_before + int(integrator.get_num_steps_taken()))
    metrics, series, after = run.finish(context, integrator)
    warnings = warnings + after
    if failure:
        metrics["failure"] = failure
    reasons = _verdict(world, metrics, scenario.criteria)
    metrics["status"] = "failed" if failure else ("missed" if reasons else "ok")
    metrics["reasons"] = [str(r) for r in reasons]
    metrics["reason_codes"] = [r.as_dict() for r in reasons]
    metrics |= {"criteria": dataclasses.asdict(scenario.criteria), "warnings": warnings,
                "warnings_before_run": n_before,
                "controller": {"type": run.controller.name, "notes": run.controller.notes,
                               "model_based": run.controller.model_based}}
    total = time.perf_counter() - t_start
    metrics["sim"] = _sim_info(scenario, run, integrator, context.get_time(), total, wall)
    metrics["sim"]["steps"] += steps_before
    return RunResult(scenario, metrics, series)


def _verdict(world, metrics: dict, criteria) -> list:
    from ptint_drake.verdict.metrics import Reason  # noqa: PLC0415

    if metrics.get("failure"):
        return [Reason(None, "failed", metrics["failure"]["message"])]
    return world.reasons(metrics, criteria)


def _sim_info(scenario: Scenario, run: WorldRun, integrator, t_end: float, total: float, wall: float) -> dict:
    """metrics.json's ``sim`` block: the run's settings, its times and its integrator's work."""
    return {"controller": scenario.controller.type,
            "control_period": scenario.controller.control_period,  # s; 0: continuous control
            "plant_time_step": run.plant_time_step,
            **run.sim_info(integrator),
            "simulated_s": t_end, "wall_time_s": total, "simulation_wall_time_s": wall,
            "realtime_factor": t_end / total if total > 0 else float("inf"),
            "simulation_realtime_factor": t_end / wall if wall > 0 else float("inf"),
            "steps": int(integrator.get_num_steps_taken())}
