"""Build the Drake diagram of a scenario, check it against the robot, run it, measure it.

The plant is continuous (``time_step = 0``) so that the scenario's
``SimulatorConfig`` (error-controlled by default) integrates the whole loop.
The simulator is stopped at exactly every segment's start, start + tf/2 and
start + tf (SPEC section 5.3): ``AdvanceTo`` lands on those times, no log is
interpolated.  Logging is per integrator step (it adds no step-size cap): with
the fused interceptor (default) only C++ state ports are logged and the
telemetry is recomputed from them after the run; with the wired blocks every
block's outputs are logged.  Metrics use the error against the *true* target
(the controller may see a measured one, ``measurement``).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder, EventStatus
from pydrake.systems.primitives import LogVectorOutput, Saturation

from ptint_drake.systems.builder import AddPrescribedTimeInterceptor, ControllerGains, InterceptorHandles
from ptint_drake.systems.disturbance import JointDisturbance
from ptint_drake.systems.measurement import MeasuredTarget
from ptint_drake.robot import (actuator_effort_limits, check_reachable, effort_limits, make_plant,
                               scale_masses, singularity_warnings, torque_feasibility)
from ptint_drake.scenario import Scenario, ScenarioError
from ptint_drake.systems.targets import active_target_state

# Logged signals: name -> (system attribute of the handles or "plant", output port name).
_LOGGED = {
    "state": ("plant", "state"),
    "x": ("kinematics", "x"),
    "xdot": ("kinematics", "xdot"),
    "x_r": ("targets", "x_r"),
    "xdot_r": ("targets", "xdot_r"),
    "xddot_r": ("targets", "xddot_r"),
    "objects": ("targets", "objects"),
    "xi": ("tbg", "xi"),
    "alpha": ("tbg", "alpha"),
    "e": ("surface", "e"),
    "edot": ("surface", "edot"),
    "s": ("surface", "s"),
    "s_d": ("surface", "s_d"),
    "s_x": ("surface", "s_x"),
    "sigma": ("surface", "sigma"),
    "tau": ("controller", "tau"),
}


@dataclass
class Built:
    diagram: object
    plant: MultibodyPlant
    handles: InterceptorHandles
    loggers: dict
    true_targets: list
    effort_limits: np.ndarray  # per generalized velocity (inf where none)


def controller_targets(scenario: Scenario) -> list:
    """What the controller is given: the true targets, or their camera measurement."""
    targets = scenario.targets()
    m = scenario.measurement
    if m.noise_std == 0.0 and m.latency == 0.0:
        return targets
    return [MeasuredTarget(tg, scenario.duration, m.noise_std, m.rate_hz, m.latency,
                           m.compensate_latency, m.seed + i) for i, tg in enumerate(targets)]


def build(scenario: Scenario, log: bool = True) -> Built:
    """The scenario's diagram: continuous plant + interceptor (+ per-step loggers if ``log``),
    with torque saturation, joint disturbance/friction and target measurement as configured."""
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("plant", make_plant(scenario))
    c = scenario.controller
    gains = ControllerGains(**{f.name: getattr(c, f.name) for f in dataclasses.fields(ControllerGains)})
    fused = c.implementation == "fused"
    handles = AddPrescribedTimeInterceptor(
        builder, plant, plant.GetFrameByName(scenario.robot.end_effector),
        scenario.schedule(), controller_targets(scenario), gains, fused=fused,
        connect_actuation=False)
    u = (handles.fused or handles.controller).GetOutputPort("u")
    limits = effort_limits(plant)
    if scenario.limits.saturate:
        actuator_limits = actuator_effort_limits(plant)
        saturation = builder.AddNamedSystem("saturation", Saturation(-actuator_limits, actuator_limits))
        builder.Connect(u, saturation.get_input_port())
        builder.Connect(saturation.get_output_port(), plant.get_actuation_input_port())
    else:
        builder.Connect(u, plant.get_actuation_input_port())
    if JointDisturbance.needed(scenario.plant):
        p, d = scenario.plant, scenario.plant.disturbance
        try:
            disturbance = builder.AddNamedSystem("disturbance", JointDisturbance(
                plant.num_positions(), plant.num_velocities(), d.amplitude, d.frequency_hz,
                d.phase, d.step, d.step_time, p.coulomb, p.coulomb_speed))
        except ValueError as exc:
            raise ScenarioError(str(exc)) from None
        builder.Connect(plant.get_state_output_port(), disturbance.get_input_port())
        builder.Connect(disturbance.get_output_port(), plant.get_applied_generalized_force_input_port())
    loggers = {}
    if log and fused:  # states only: telemetry is recomputed afterwards (see interceptor.py)
        loggers["state"] = LogVectorOutput(plant.get_state_output_port(), builder, publish_period=0.0)
        for port in ("sigma", "captured"):
            loggers[port] = LogVectorOutput(handles.fused.GetOutputPort(port), builder,
                                            publish_period=0.0)
    for name, (owner, port) in (_LOGGED.items() if log and not fused else ()):
        system = plant if owner == "plant" else getattr(handles, owner)
        source = plant.get_state_output_port() if owner == "plant" else system.GetOutputPort(port)
        loggers[name] = LogVectorOutput(source, builder, publish_period=0.0)
    diagram = builder.Build()
    diagram.set_name(scenario.name or "ptint")
    return Built(diagram, plant, handles, loggers, scenario.targets(), limits)


@dataclass
class RunResult:
    scenario: Scenario
    metrics: dict
    series: dict = field(repr=False)

    @property
    def failed(self) -> bool:
        return self.metrics.get("status") == "failed"


_SUCCEEDED = EventStatus.Succeeded()


class _Watchdog:
    """Simulator monitor: progress reports and the divergence checks.

    Every 10th step (a Python call per step is all the other steps cost) the
    plant state must be finite and every joint speed within ``limits.max_joint_speed``;
    every 50th step |e| (against the true target, one extra evaluation of the
    interceptor) within ``limits.max_error``.  A violation
    ends the simulation (ReachedTermination) with a message saying when and which
    quantity.  An integrator failure is caught by ``simulate`` the same way.
    """

    def __init__(self, scenario, plant, plant_context_of, position_of, true_target, progress):
        self.failure = None
        self._scenario = scenario
        self._nq = plant.num_positions()
        self._state_port = plant.get_state_output_port()
        self._plant_context_of = plant_context_of
        self._position_of = position_of
        self._true_target = true_target
        self._progress = progress
        self._last = 0.0
        self._count = 0

    def __call__(self, context):
        self._count += 1
        if self._count % 10:
            return _SUCCEEDED
        t = context.get_time()
        qv = self._state_port.Eval(self._plant_context_of(context))
        limits = self._scenario.limits
        if not np.all(np.isfinite(qv)):
            return self._fail(t, "the plant state is not finite")
        speed = float(np.max(np.abs(qv[self._nq:]))) if len(qv) > self._nq else 0.0
        if speed > limits.max_joint_speed:
            return self._fail(t, f"joint speed {speed:.3g} exceeds limits.max_joint_speed "
                                 f"= {limits.max_joint_speed:g}")
        if self._count % 50:
            return _SUCCEEDED
        err = float(np.linalg.norm(self._position_of(context) - self._true_target(t)))
        if not np.isfinite(err) or err > limits.max_error:
            return self._fail(t, f"interception error |e| = {err:.3g} m exceeds "
                                 f"limits.max_error = {limits.max_error:g} m")
        return self._report(t)

    def _report(self, t):
        if self._progress is not None:
            now = time.perf_counter()
            if now - self._last > 0.2:
                self._last = now
                self._progress(t, self._scenario.duration)
        return _SUCCEEDED

    def _fail(self, t, what):
        self.failure = {"time": t, "message": f"diverged at t = {t:.4f} s: {what}"}
        return EventStatus.ReachedTermination(None, self.failure["message"])

    def integration_failed(self, t, exc):
        detail = " ".join(str(exc).split())[:300]
        self.failure = {"time": t, "message": f"integration failed at t = {t:.4f} s: {detail}"}


def simulate(scenario: Scenario, check: bool = True, progress=None) -> RunResult:
    """Run a scenario; returns SPEC 5.3 metrics and the logged time series.

    ``progress(t, duration)`` is called while it runs.  A run stopped by the
    divergence watchdog returns normally with ``metrics["status"] == "failed"``
    and everything computed until then.
    """
    built = build(scenario)
    warnings = []
    if check:
        check_reachable(built.plant, scenario)
        warnings += torque_feasibility(built.plant, scenario)
    diagram, plant, h = built.diagram, built.plant, built.handles
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    context = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    scale_masses(plant, plant_context, scenario.plant.mass_scale)
    plant.SetPositions(plant_context, np.radians(scenario.robot.initial_q_deg))
    plant.SetVelocities(plant_context, np.zeros(plant.num_velocities()))
    if h.fused is not None:
        telemetry = h.fused.GetOutputPort("telemetry")
        layout = h.fused.layout

        def robot_point(ctx):
            value = telemetry.Eval(h.fused.GetMyContextFromRoot(ctx))
            return value[layout["x"]].copy(), value[layout["xdot"]].copy()
    else:
        def robot_point(ctx):
            kc = h.kinematics.GetMyContextFromRoot(ctx)
            return (h.kinematics.GetOutputPort("x").Eval(kc).copy(),
                    h.kinematics.GetOutputPort("xdot").Eval(kc).copy())

    true_state = lambda t: active_target_state(h.schedule, built.true_targets, t)  # noqa: E731
    watchdog = _Watchdog(scenario, plant, plant.GetMyContextFromRoot, lambda c: robot_point(c)[0],
                         lambda t: true_state(t)[0:3], progress)
    simulator.set_monitor(watchdog)

    schedule = h.schedule
    stops = {scenario.duration}
    for seg in schedule.segments:
        stops.update({seg.start, seg.start + 0.5 * seg.tf, seg.end})
    samples = {}
    wall = 0.0
    simulator.Initialize()
    for t_stop in sorted(stops):
        if t_stop > context.get_time():
            t0 = time.perf_counter()
            try:
                simulator.AdvanceTo(t_stop)
            except RuntimeError as exc:  # e.g. a step-size collapse on a non-finite state
                watchdog.integration_failed(context.get_time(), exc)
            wall += time.perf_counter() - t0
        if watchdog.failure is not None:
            break
        x, xdot = robot_point(context)
        target = true_state(t_stop)
        samples[t_stop] = (x - target[0:3], xdot - target[3:6])
    if progress is not None:
        progress(context.get_time(), scenario.duration)

    series = collect_series(built, context)
    t_end = context.get_time()
    integrator = simulator.get_integrator()
    metrics = compute_metrics(scenario, samples, series, built.effort_limits)
    warnings += singularity_warnings(plant, scenario, series)
    metrics["status"] = "failed" if watchdog.failure else "ok"
    if watchdog.failure:
        metrics["failure"] = watchdog.failure
    metrics["warnings"] = warnings
    metrics["sim"] = {
        "integration_scheme": scenario.simulator.integration_scheme,
        "accuracy": scenario.simulator.accuracy,
        "switching": scenario.controller.switching,
        "implementation": scenario.controller.implementation,
        "simulated_s": t_end,
        "wall_time_s": wall,
        "realtime_factor": t_end / wall if wall > 0 else float("inf"),
        "steps": int(integrator.get_num_steps_taken()),
        "derivative_evaluations": int(integrator.get_num_derivative_evaluations()),
    }
    return RunResult(scenario, metrics, series)


def collect_series(built: Built, context) -> dict:
    """The per-step logs as arrays (fused runs: telemetry recomputed from logged states),
    plus the true targets' positions (``objects``) and the error against the true target."""
    h, plant = built.handles, built.plant
    series = {}
    for name, logger in built.loggers.items():
        log = logger.FindLog(context)
        series[name] = log.data().T.copy()
        series["t"] = log.sample_times().copy()
    t = series["t"]
    if h.fused is not None:
        telemetry = h.fused.telemetry_at(t, series["state"], series.pop("sigma"),
                                         series.pop("captured"))
        for name, part in h.fused.layout.items():
            series[name] = telemetry[:, part]
    truth = np.array([np.concatenate([tg.evaluate(tk)[0:6] for tg in built.true_targets])
                      for tk in t]).reshape(len(t), -1, 6)
    series["objects"] = truth[:, :, 0:3].reshape(len(t), -1)
    active = np.array([max(h.schedule.active(tk), 0) for tk in t], dtype=int)
    own = truth[np.arange(len(t)), active]
    series["e_true"] = series["x"] - own[:, 0:3]
    series["edot_true"] = series["xdot"] - own[:, 3:6]
    nq = plant.num_positions()
    series["q"] = series["state"][:, :nq]
    series["v"] = series["state"][:, nq:]
    del series["state"]
    series["tau_applied"] = np.clip(series["tau"], -built.effort_limits, built.effort_limits) \
        if built.diagram.HasSubsystemNamed("saturation") else series["tau"].copy()
    return series


def compute_metrics(scenario: Scenario, samples: dict, series: dict, limits: np.ndarray) -> dict:
    """SPEC 5.3 metrics from the exact stops (``samples``: error against the true target)
    and the per-step log.  Segments the run did not reach have ``null`` values."""
    schedule = scenario.schedule()
    t = series["t"]
    e_norm = np.linalg.norm(series["e_true"], axis=1)
    segments = []
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, scenario.duration)
        row = {"start": seg.start, "tf": seg.tf, "beta": seg.beta, "hold_end": t_end}
        for key, at, which in (("e0_norm", seg.start, 0), ("e_half_norm", seg.start + 0.5 * seg.tf, 0),
                               ("e_tf_norm", seg.end, 0), ("edot_tf_norm", seg.end, 1)):
            row[key] = float(np.linalg.norm(samples[at][which])) if at in samples else None
        hold = (t >= seg.end) & (t < t_end)
        if row["e_tf_norm"] is None:
            row["e_hold_max_norm"] = None
        else:
            row["e_hold_max_norm"] = max(float(np.max(e_norm[hold])) if hold.any() else 0.0,
                                         row["e_tf_norm"])
        segments.append(row)
    tau = series["tau"]
    over = np.any(np.abs(tau) > limits * (1.0 + 1e-9), axis=1)
    dt = np.diff(t, append=t[-1]) if len(t) else np.zeros(0)
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    return {
        "scenario": scenario.name,
        "duration": scenario.duration,
        "segments": segments,
        "torque_peak": np.max(np.abs(series["tau_applied"]), axis=0).tolist(),
        "torque_command_peak": np.max(np.abs(tau), axis=0).tolist(),
        "effort_limits": limits.tolist(),
        "saturated_fraction": float(np.sum(dt[over]) / span) if span > 0 else 0.0,
    }
