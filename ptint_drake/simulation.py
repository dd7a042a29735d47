"""Build the Drake diagram of a scenario, check it against the robot, run it, measure it.

The plant is continuous (``time_step = 0``) so that the scenario's
``SimulatorConfig`` (error-controlled by default) integrates the whole loop.
The simulator is stopped at exactly every segment's start, start + tf/2 and
start + tf (SPEC section 5.3): ``AdvanceTo`` lands on those times, no log is
interpolated.  Every block's outputs are logged once per integrator step
(per-step logging adds no step-size cap).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import (BodyIndex, JointIndex, PrismaticJoint, RevoluteJoint,
                                    SpatialInertia)
from pydrake.solvers import Solve
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder, EventStatus
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.builder import AddPrescribedTimeInterceptor, ControllerGains, InterceptorHandles
from ptint_drake.rvm1 import bundled_models, model_path
from ptint_drake.scenario import Scenario, ScenarioError

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


def resolve_model(model: str) -> Path:
    """A bundled model name or a model file path; ScenarioError if neither exists."""
    if model in bundled_models():
        return model_path(model)
    path = Path(model)
    if not path.is_file():
        raise ScenarioError(
            f"robot.model: {model!r} is neither a bundled model ({', '.join(bundled_models())}) "
            f"nor an existing file")
    return path


def make_plant(scenario: Scenario) -> MultibodyPlant:
    """The continuous plant of the scenario's robot, with its damping scale applied."""
    plant = MultibodyPlant(time_step=0.0)
    path = resolve_model(scenario.robot.model)
    try:
        Parser(plant).AddModels(str(path))
    except Exception as exc:
        raise ScenarioError(f"robot.model: cannot parse {str(path)!r}: {' '.join(str(exc).split())[:300]}") from None
    for i in range(plant.num_joints()):
        joint = plant.get_joint(JointIndex(i))
        if isinstance(joint, (RevoluteJoint, PrismaticJoint)):
            joint.set_default_damping(joint.default_damping() * scenario.plant.damping_scale)
    plant.Finalize()
    if not plant.HasFrameNamed(scenario.robot.end_effector):
        raise ScenarioError(
            f"robot.end_effector: the model has no frame named {scenario.robot.end_effector!r}")
    if len(scenario.robot.initial_q_deg) != plant.num_positions():
        raise ScenarioError(
            f"robot.initial_q_deg: the model has {plant.num_positions()} joints, "
            f"got {len(scenario.robot.initial_q_deg)} angles")
    return plant


def scale_masses(plant: MultibodyPlant, plant_context, scale: float) -> None:
    """Every link's mass and rotational inertia × scale (rotor inertias unchanged)."""
    if scale == 1.0:
        return
    for index in range(1, plant.num_bodies()):
        body = plant.get_body(BodyIndex(index))
        M = body.default_spatial_inertia()
        if M.get_mass() > 0.0:
            body.SetSpatialInertiaInBodyFrame(plant_context, SpatialInertia(
                M.get_mass() * scale, M.get_com(), M.get_unit_inertia()))


def check_reachable(plant: MultibodyPlant, scenario: Scenario, samples_per_hold: int = 4) -> None:
    """Every target must be reachable at its interception time and during its hold.

    Reachability is decided by Drake's InverseKinematics with the model's joint
    limits (1 mm tolerance), started from the initial pose and from the previous
    solution.  Raises ScenarioError naming the interception.
    """
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    schedule = scenario.schedule()
    targets = scenario.targets()
    guess = np.radians(scenario.robot.initial_q_deg)
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, scenario.duration)
        for t in np.linspace(seg.end, max(t_end, seg.end), samples_per_hold):
            x = targets[i].evaluate(t)[0:3]
            ik = InverseKinematics(plant, with_joint_limits=True)
            ik.AddPositionConstraint(frame, np.zeros(3), plant.world_frame(),
                                     x - 1e-3, x + 1e-3)
            ik.prog().SetInitialGuess(ik.q(), guess)
            result = Solve(ik.prog())
            if not result.is_success():
                raise ScenarioError(
                    f"interceptions[{i}].target: position {np.round(x, 4).tolist()} m at "
                    f"t = {t:.3f} s is outside the arm's workspace")
            guess = result.GetSolution(ik.q())


@dataclass
class Built:
    diagram: object
    plant: MultibodyPlant
    handles: InterceptorHandles
    loggers: dict


def build(scenario: Scenario, log: bool = True) -> Built:
    """The scenario's diagram: continuous plant + interceptor (+ per-step loggers if ``log``)."""
    builder = DiagramBuilder()
    plant = builder.AddNamedSystem("plant", make_plant(scenario))
    c = scenario.controller
    gains = ControllerGains(c.K, c.Lambda, c.k, c.epsilon, c.delta, c.alpha_hold,
                            c.switching, c.phi, c.sigma_policy, c.k_hold)
    fused = c.implementation == "fused"
    handles = AddPrescribedTimeInterceptor(
        builder, plant, plant.GetFrameByName(scenario.robot.end_effector),
        scenario.schedule(), scenario.targets(), gains, fused=fused)
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
    return Built(diagram, plant, handles, loggers)


@dataclass
class RunResult:
    scenario: Scenario
    metrics: dict
    series: dict = field(repr=False)


def simulate(scenario: Scenario, check: bool = True, progress=None) -> RunResult:
    """Run a scenario; returns SPEC 5.3 metrics and the logged time series.

    ``progress(t, duration)`` is called at every stop of the simulator.
    """
    built = build(scenario)
    if check:
        check_reachable(built.plant, scenario)
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
        fused_context = h.fused.GetMyContextFromRoot(context)
        layout = h.fused.layout

        def error_now():
            value = telemetry.Eval(fused_context)
            return value[layout["e"]].copy(), value[layout["edot"]].copy()
    else:
        surface_context = h.surface.GetMyContextFromRoot(context)

        def error_now():
            return (h.surface.GetOutputPort("e").Eval(surface_context).copy(),
                    h.surface.GetOutputPort("edot").Eval(surface_context).copy())

    schedule = h.schedule
    stops = {scenario.duration}
    for seg in schedule.segments:
        stops.update({seg.start, seg.start + 0.5 * seg.tf, seg.end})
    samples = {}
    wall = 0.0
    if progress is not None:
        last = [0.0]

        def monitor(ctx):
            now = time.perf_counter()
            if now - last[0] > 0.2:
                last[0] = now
                progress(ctx.get_time(), scenario.duration)
            return EventStatus.Succeeded()

        simulator.set_monitor(monitor)
    simulator.Initialize()
    for t_stop in sorted(stops):
        if t_stop > context.get_time():
            t0 = time.perf_counter()
            simulator.AdvanceTo(t_stop)
            wall += time.perf_counter() - t0
        samples[t_stop] = error_now()

    if progress is not None:
        progress(scenario.duration, scenario.duration)
    series = {}
    for name, logger in built.loggers.items():
        log = logger.FindLog(context)
        series[name] = log.data().T.copy()
        series["t"] = log.sample_times().copy()
    if h.fused is not None:
        telemetry = h.fused.telemetry_at(series["t"], series["state"], series.pop("sigma"),
                                         series.pop("captured"))
        for name, part in h.fused.layout.items():
            series[name] = telemetry[:, part]
        targets = scenario.targets()
        series["objects"] = np.array([np.concatenate([tg.evaluate(tk)[0:3] for tg in targets])
                                      for tk in series["t"]])
    nq = plant.num_positions()
    series["q"] = series["state"][:, :nq]
    series["v"] = series["state"][:, nq:]
    del series["state"]

    integrator = simulator.get_integrator()
    metrics = compute_metrics(scenario, samples, series)
    metrics["sim"] = {
        "integration_scheme": scenario.simulator.integration_scheme,
        "accuracy": scenario.simulator.accuracy,
        "switching": scenario.controller.switching,
        "wall_time_s": wall,
        "realtime_factor": scenario.duration / wall if wall > 0 else float("inf"),
        "steps": int(integrator.get_num_steps_taken()),
        "derivative_evaluations": int(integrator.get_num_derivative_evaluations()),
    }
    return RunResult(scenario, metrics, series)


def compute_metrics(scenario: Scenario, samples: dict, series: dict) -> dict:
    """SPEC 5.3 metrics from the exact stops (``samples``) and the per-step log."""
    schedule = scenario.schedule()
    t = series["t"]
    e_norm = np.linalg.norm(series["e"], axis=1)
    segments = []
    for i, seg in enumerate(schedule.segments):
        e0, _ = samples[seg.start]
        e_half, _ = samples[seg.start + 0.5 * seg.tf]
        e_tf, edot_tf = samples[seg.end]
        t_end = schedule.hold_end(i, scenario.duration)
        hold = (t >= seg.end) & (t < t_end)
        hold_max = max(float(np.max(e_norm[hold])) if hold.any() else 0.0,
                       float(np.linalg.norm(e_tf)))
        segments.append({
            "start": seg.start, "tf": seg.tf, "beta": seg.beta,
            "e0_norm": float(np.linalg.norm(e0)),
            "e_half_norm": float(np.linalg.norm(e_half)),
            "e_tf_norm": float(np.linalg.norm(e_tf)),
            "edot_tf_norm": float(np.linalg.norm(edot_tf)),
            "e_hold_max_norm": hold_max,
            "hold_end": t_end,
        })
    return {
        "scenario": scenario.name,
        "duration": scenario.duration,
        "segments": segments,
        "torque_peak": np.max(np.abs(series["tau"]), axis=0).tolist(),
    }
