"""Build a scenario's diagram (station + controller), check it against the robot, run it.

The plant is continuous (``time_step = 0``) so that the scenario's
``SimulatorConfig`` (error-controlled by default) integrates the whole loop; a scenario's
``multibody`` block makes it discrete (Drake's ``MultibodyPlantConfig``), and
``controller.control_period`` puts the drive's zero-order hold before it (``controllers.hold``):
the simulator then also stops at every sample.
The simulator is stopped at exactly every segment's start, start + tf/2 and
start + tf: ``AdvanceTo`` lands on those times, no log is interpolated.
Logging is per integrator step (it adds no step-size cap): the station's plant
state always, and whatever the controller declares (the fused interceptor logs
only its state ports and recomputes its telemetry afterwards).  The metrics
(``metrics.py``) use the gripper point computed from the logged plant state and
the true objects — never the controller's own view.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.controllers import AddController, ControllerHandles
from ptint_drake.metrics import run_metrics, verdict
from ptint_drake.reachability import check_reachable
from ptint_drake.run_warnings import (joint_limit_warnings, sampled_control_warnings, singularity_warnings,
                                     torque_feasibility)
from ptint_drake.scenario import Scenario
from ptint_drake.station import MakeStation, Station
from ptint_drake.systems.kinematics import FrameKinematics
from ptint_drake.systems.orientation import rotation_error, target_rotation_values
from ptint_drake.systems.signals import TARGET
from ptint_drake.systems.stateless_derivatives import install_stateless_derivatives
from ptint_drake.systems.targets import active_target_values, target_values
from ptint_drake.systems.task import task_reference
from ptint_drake.watchdog import Watchdog


@dataclass
class Built:
    diagram: object
    station: Station
    controller: ControllerHandles
    loggers: dict
    schedule: object

    @property
    def plant(self):
        return self.station.plant


def build(scenario: Scenario, log: bool = True) -> Built:
    """The scenario's diagram: the station, the controller in its slot, and (``log``)
    per-step loggers of the plant state and the controller's declared ports."""
    builder = DiagramBuilder()
    station = MakeStation(scenario)
    station_system = builder.AddSystem(station.diagram)
    controller = AddController(builder, station_system, station, scenario)
    loggers = {}
    if log:
        loggers["state"] = LogVectorOutput(station_system.GetOutputPort("state"), builder,
                                           publish_period=0.0)
        for name, port in controller.log_ports.items():
            loggers[name] = LogVectorOutput(port, builder, publish_period=0.0)
    diagram = builder.Build()
    diagram.set_name(scenario.name or "ptint")
    install_stateless_derivatives(diagram)  # Drake's nanobind bindings: ~10 µs per leaf saved
    return Built(diagram, station, controller, loggers, scenario.schedule())


@dataclass
class RunResult:
    scenario: Scenario
    metrics: dict
    series: dict = field(repr=False)

    @property
    def failed(self) -> bool:
        return self.metrics.get("status") == "failed"

    @property
    def ok(self) -> bool:
        return self.metrics.get("status") == "ok"


def pre_run_warnings(built: Built, scenario: Scenario) -> list[str]:
    """Checks before simulating: reachability (raises ScenarioError), torque feasibility and the
    control period."""
    check_reachable(built.plant, scenario)
    return torque_feasibility(built.plant, scenario) + sampled_control_warnings(scenario)


def _stops(scenario: Scenario) -> list[float]:
    stops = {scenario.duration}
    for seg in scenario.schedule().segments:
        stops.update({seg.start, seg.start + 0.5 * seg.tf, seg.end})
    return sorted(stops)


def prepared_simulator(built: Built, scenario: Scenario) -> Simulator:
    """A simulator of the built diagram with the scenario's integrator settings, from the
    diagram's default context (the station's defaults are the scenario's start)."""
    simulator = Simulator(built.diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    return simulator


def _advance(simulator: Simulator, scenario: Scenario, watchdog: Watchdog, gripper, true_state,
             plugin: bool = False):
    """Run to every exact stop; returns (samples: t → (e, ė) against the true target, wall s).
    With a user's controller (``plugin``), an exception it raises fails the run."""
    context = simulator.get_mutable_context()
    samples, wall = {}, 0.0
    simulator.Initialize()
    for t_stop in _stops(scenario):
        if t_stop > context.get_time():
            t0 = time.perf_counter()
            try:
                simulator.AdvanceTo(t_stop)
            except RuntimeError as exc:  # e.g. a step-size collapse on a non-finite state
                watchdog.integration_failed(context.get_time(), exc)
            except Exception as exc:  # noqa: BLE001  (only a plugin's: the package's own are bugs)
                if not plugin:
                    raise
                watchdog.controller_failed(context.get_time(), scenario.controller.type, exc)
            wall += time.perf_counter() - t0
        if watchdog.failure is not None:
            break
        x, xdot, _ = gripper(context)
        target = true_state(t_stop)
        samples[t_stop] = (x - target[TARGET.x], xdot - target[TARGET.xdot])
    return samples, wall


def simulate(scenario: Scenario, check: bool = True, progress=None,
             warn: Optional[Callable[[str], None]] = None) -> RunResult:
    """Run a scenario; returns its metrics (with the verdict) and the logged time series.

    ``progress(t, duration, steps)`` is called while it runs; ``warn(message)`` is called for
    each warning known before the simulation starts, as soon as it is known.  A run
    stopped by the divergence watchdog returns normally with ``status == "failed"``.  A pick
    scenario (``pick``) runs through ``pick.run.simulate_pick``.
    """
    if scenario.pick is not None:
        from ptint_drake.pick.run import simulate_pick  # noqa: PLC0415

        return simulate_pick(scenario, check, progress, warn)
    built = build(scenario)
    warnings = pre_run_warnings(built, scenario) if check else []
    for message in warnings if warn is not None else ():
        warn(message)
    n_before = len(warnings)
    plant = built.plant
    kinematics = FrameKinematics(plant, plant.GetFrameByName(scenario.robot.end_effector))
    t_start = time.perf_counter()  # the realtime factor counts simulation, telemetry, metrics
    simulator = prepared_simulator(built, scenario)
    nq = plant.num_positions()

    def gripper(ctx):
        qv = plant.get_state_output_port().Eval(plant.GetMyContextFromRoot(ctx))
        return kinematics.compute(qv[:nq], qv[nq:])

    schedule, targets = scenario.schedule(), built.station.true_targets
    true_state = lambda t: active_target_values(schedule, targets, t)  # noqa: E731
    watchdog = Watchdog(scenario=scenario, diagram=built.diagram, plant=plant,
                        position_of=lambda c: gripper(c)[0], true_target=lambda t: true_state(t)[TARGET.x],
                        progress=progress)
    simulator.set_monitor(watchdog)
    samples, wall = _advance(simulator, scenario, watchdog, gripper, true_state, built.controller.plugin)
    context, integrator = simulator.get_context(), simulator.get_integrator()
    if progress is not None:
        progress(context.get_time(), scenario.duration, int(integrator.get_num_steps_taken()))
    series = collect_series(built, context, kinematics)
    if scenario.controller.task != "position":
        series |= orientation_series(scenario.controller.task, kinematics, series, built.station.true_targets,
                                     scenario.schedule(), scenario.duration)
    metrics = run_metrics(scenario, samples, series, built.station.effort_limits)
    warnings += singularity_warnings(scenario, series) + joint_limit_warnings(plant, series)
    if watchdog.failure:
        metrics["failure"] = watchdog.failure
    metrics["status"], reasons = verdict(metrics, scenario.criteria)
    metrics["reasons"] = [str(r) for r in reasons]
    metrics["reason_codes"] = [r.as_dict() for r in reasons]
    metrics |= {"criteria": dataclasses.asdict(scenario.criteria), "warnings": warnings,
                "warnings_before_run": n_before,
                "controller": {"type": built.controller.name, "notes": built.controller.notes,
                               "model_based": built.controller.model_based}}
    metrics["sim"] = _sim_info(scenario, integrator, context.get_time(),
                               time.perf_counter() - t_start, wall)
    return RunResult(scenario, metrics, series)


def _sim_info(scenario: Scenario, integrator, t_end: float, total: float, wall: float) -> dict:
    """The ``sim`` block of metrics.json; ``realtime_factor`` is end to end (simulation,
    telemetry, metrics), ``simulation_realtime_factor`` the simulation alone."""
    return {
        "integration_scheme": scenario.simulator.integration_scheme,
        "accuracy": scenario.simulator.accuracy,
        "switching": scenario.controller.switching,
        "implementation": scenario.controller.implementation,
        "controller": scenario.controller.type,
        "control_period": scenario.controller.control_period,  # s; 0: continuous control
        "plant_time_step": scenario.multibody.time_step if scenario.multibody is not None else 0.0,
        "simulated_s": t_end,
        "wall_time_s": total,
        "simulation_wall_time_s": wall,
        "realtime_factor": t_end / total if total > 0 else float("inf"),
        "simulation_realtime_factor": t_end / wall if wall > 0 else float("inf"),
        "steps": int(integrator.get_num_steps_taken()),
        "derivative_evaluations": int(integrator.get_num_derivative_evaluations()),
    }


def collect_series(built: Built, context, kinematics: FrameKinematics) -> dict:
    """The per-step logs as arrays: t, q, v, the controller's telemetry, the gripper point
    from the plant state with J's smallest singular value (``sigma_min_J``, m/rad, for
    ``run_warnings.singularity_warnings``), the true objects and the error against the active
    true target."""
    logs = {}
    for name, logger in built.loggers.items():
        log = logger.FindLog(context)
        logs[name] = log.data().T.copy()
        logs["t"] = log.sample_times().copy()
    t, state = logs["t"], logs["state"]
    plant, station = built.plant, built.station
    nq = plant.num_positions()
    series = dict(built.controller.telemetry(logs))
    series["t"] = t
    series["q"], series["v"] = state[:, :nq], state[:, nq:]
    x = np.empty((len(t), 3))
    xdot = np.empty((len(t), 3))
    redundant = plant.num_velocities() > 3
    self_motion = np.zeros(len(t))
    jacobians = np.empty((len(t), 3, plant.num_velocities()))
    for k in range(len(t)):
        v = state[k, nq:]
        x[k], xdot[k], J = kinematics.compute(state[k, :nq], v)
        jacobians[k] = J
        if redundant:  # |(I − J⁺J)(q − q_start)|: how far the arm wandered in its self-motion
            dq = state[k, :nq] - state[0, :nq]
            self_motion[k] = np.linalg.norm(dq - J.T @ np.linalg.solve(J @ J.T, J @ dq))
    series["x"], series["xdot"] = x, xdot
    series["sigma_min_J"] = np.linalg.svd(jacobians, compute_uv=False)[:, -1] if len(t) \
        else np.empty(0)  # J's smallest singular value (m/rad): how near a singularity
    if redundant:
        series["self_motion"] = self_motion
    targets = station.true_targets
    truth = np.array([[v for tg in targets for v in target_values(tg, tk)[0:6]]
                      for tk in t.tolist()], dtype=float).reshape(len(t), len(targets), 6)
    series["objects"] = truth[:, :, 0:3].reshape(len(t), -1)
    active = np.array([max(built.schedule.active(tk), 0) for tk in t], dtype=int)
    own = truth[np.arange(len(t)), active]
    series["e_true"] = x - own[:, 0:3]
    series["edot_true"] = xdot - own[:, 3:6]
    limits = station.effort_limits
    series["tau_applied"] = np.clip(series["tau"], -limits, limits) if station.saturate \
        else series["tau"].copy()
    return series


def orientation_series(task: str, kinematics: FrameKinematics, series: dict, targets, schedule,
                       duration: float) -> dict:
    """Per sample and per object i: the angle (deg) between the tool's orientation (forward
    kinematics of the logged plant state) and object i's TRUE orientation as the task asks for it
    (``rot_angle_deg``), and the rate of that error rotation |ω − R R_rᵀ ω_r| (``rot_rate_deg_s``),
    from segment i's start to the end of its hold (NaN elsewhere)."""
    t, q, v = series["t"], series["q"], series["v"]
    angle = np.full((len(t), len(targets)), np.nan)
    rate = np.full((len(t), len(targets)), np.nan)
    windows = [(seg.start, schedule.hold_end(i, duration)) for i, seg in enumerate(schedule.segments)]
    for k, tk in enumerate(t.tolist()):
        _, _, R, omega, _, _ = kinematics.compute_pose(q[k], v[k])
        for i, tg in enumerate(targets):
            if windows[i][0] <= tk <= windows[i][1]:
                reference = task_reference(task, target_rotation_values(tg, tk), R)
                e_R, edot_R = rotation_error(R, omega, reference)
                angle[k, i], rate[k, i] = np.linalg.norm(e_R), np.linalg.norm(edot_R)
    return {"rot_angle_deg": np.degrees(angle), "rot_rate_deg_s": np.degrees(rate)}
