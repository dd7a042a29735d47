"""The controller slot: the scenario's ``controller.type`` chosen and wired to the station.

Every controller connects to the station's ports the same way — ``state`` in,
a target in, ``u`` out to ``actuation`` — and declares its own telemetry: the
ports to log at every integrator step and a function that turns those logs
into named signals (at least ``x``, ``xdot``, ``tau``).

What the controller sees of the target (``target_view``): with
``measurement.estimator: none`` the analytic target (or its legacy noisy/delayed
version, ``measurement.noise_std``/``latency``); with an estimator, only what a
camera and a Kalman filter make of the true objects.  The station's true
target never reaches a controller directly.

Controllers (``CONTROLLERS``): ``ptsmc``, the paper's interceptor (model-free);
``pd`` (task-space PID) and ``smc`` (first-order sliding mode, no TBG), both
model-free; ``ct_quintic`` (quintic joint plan tracked by inverse dynamics of the
*nominal* model, given the target's future) — the model-based reference.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
from pydrake.systems.framework import DiagramBuilder, OutputPort
from pydrake.systems.primitives import Demultiplexer

from ptint_drake.robot import make_plant
from ptint_drake.scenario import PlantConfig, Scenario
from ptint_drake.station import Station
from ptint_drake.systems.builder import AddPrescribedTimeInterceptor, InterceptorHandles
from ptint_drake.systems.gains import ControllerGains
from ptint_drake.systems.ct_quintic import CtQuinticController
from ptint_drake.systems.kalman import AddCameraEstimators
from ptint_drake.systems.pd import PDController
from ptint_drake.systems.signals import TARGET
from ptint_drake.systems.smc import FirstOrderSMC, SMCConfig
from ptint_drake.systems.measurement import MeasuredTarget
from ptint_drake.systems.targets import TargetSource

# Logged signals of the wired blocks: name -> (handle attribute, output port name).
_BLOCK_PORTS = {
    "x": ("kinematics", "x"), "xdot": ("kinematics", "xdot"),
    "xi": ("tbg", "xi"), "alpha": ("tbg", "alpha"),
    "e": ("surface", "e"), "edot": ("surface", "edot"), "s": ("surface", "s"),
    "s_d": ("surface", "s_d"), "s_x": ("surface", "s_x"), "sigma": ("surface", "sigma"),
    "tau": ("controller", "tau"),
}


@dataclass
class ControllerHandles:
    """What the slot added: the ports to log every step, how to turn those logs into
    telemetry (a dict of arrays, rows = samples), and lines for the run's output."""

    name: str
    log_ports: dict
    telemetry: Callable[[dict], dict]
    notes: list = field(default_factory=list)
    model_based: bool = False
    system: object = None


def controller_targets(scenario: Scenario) -> list:
    """The analytic view: the true targets, or their legacy noisy/delayed measurement."""
    targets = scenario.targets()
    m = scenario.measurement
    if m.noise_std == 0.0 and m.latency == 0.0:
        return targets
    return [MeasuredTarget(tg, scenario.duration, m.noise_std, m.rate_hz, m.latency,
                           m.compensate_latency, m.seed + i) for i, tg in enumerate(targets)]


def target_view(builder: DiagramBuilder, station_system, scenario: Scenario) -> OutputPort:
    """The port that carries [x_r, ẋ_r, ẍ_r] of the active segment as the controller sees it:
    the analytic targets (``estimator: none``), or one camera + Kalman filter per object
    fed by the station's true object positions (``kalman_cv`` / ``kalman_ca``)."""
    if uses_analytic_targets(scenario):
        source = builder.AddNamedSystem("target_view", TargetSource(
            scenario.schedule(), controller_targets(scenario)))
        return source.GetOutputPort("target")
    n = len(scenario.interceptions)
    split = builder.AddNamedSystem("object_positions", Demultiplexer([3] * n))
    builder.Connect(station_system.GetOutputPort("objects"), split.get_input_port())
    return AddCameraEstimators(builder, true_position_ports=[split.get_output_port(i) for i in range(n)],
                               schedule=scenario.schedule(), config=scenario.measurement,
                               histories=scenario.targets()).target_port  # in view before t = 0


def gains_of(scenario: Scenario) -> ControllerGains:
    c = scenario.controller
    return ControllerGains(**{name: getattr(c, name) for name in ControllerGains.__dataclass_fields__})


def _add_ptsmc(builder, station_system, station: Station, scenario: Scenario) -> ControllerHandles:
    plant = station.plant
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    fused = scenario.controller.implementation == "fused"
    analytic = uses_analytic_targets(scenario)
    h = AddPrescribedTimeInterceptor(
        builder, plant, frame, scenario.schedule(),
        controller_targets(scenario) if analytic and fused else None, gains_of(scenario),
        connect_actuation=False, fused=fused, state_port=station_system.GetOutputPort("state"),
        posture=np.radians(scenario.robot.initial_q_deg))
    system = h.fused or h.controller
    builder.Connect(system.GetOutputPort("u"), station_system.GetInputPort("actuation"))
    target = None
    if h.target_input is not None:
        target = target_view(builder, station_system, scenario)
        builder.Connect(target, h.target_input)
    notes = [f"ptsmc: K = {scenario.controller.K:g}, Λ = {scenario.controller.Lambda:g}, "
             f"k = {scenario.controller.k:g}, {scenario.controller.switching} law"]
    if fused:
        return _fused_handles(h, target, notes)
    return _block_handles(h, target, notes)


def _fused_handles(h: InterceptorHandles, target: Optional[OutputPort], notes) -> ControllerHandles:
    """The fused system logs only state ports; its telemetry is recomputed afterwards."""
    system = h.fused
    ports = {"sigma": system.GetOutputPort("sigma"), "captured": system.GetOutputPort("captured")}
    if target is not None:
        ports["target"] = target

    def telemetry(logs: dict) -> dict:
        rows = system.telemetry_at(logs["t"], logs["state"], logs["sigma"], logs["captured"],
                                   logs.get("target"))
        return {name: rows[:, part] for name, part in system.layout.items()}

    return ControllerHandles("ptsmc", ports, telemetry, notes, system=system)


def _target_columns(target_log: np.ndarray) -> dict:
    """x_r, ẋ_r, ẍ_r of a logged target port (what the controller saw)."""
    return {"x_r": target_log[:, TARGET.x], "xdot_r": target_log[:, TARGET.xdot],
            "xddot_r": target_log[:, TARGET.xddot]}


def _block_handles(h: InterceptorHandles, target: Optional[OutputPort], notes) -> ControllerHandles:
    ports = {}
    for name, (owner, port) in _BLOCK_PORTS.items():
        ports[name] = getattr(h, owner).GetOutputPort(port)
    if h.target_input is None:
        ports["target"] = h.targets.GetOutputPort("target")
    else:
        ports["target"] = target

    def telemetry(logs: dict) -> dict:
        out = {name: logs[name] for name in ports}
        out |= _target_columns(out.pop("target"))
        return out

    return ControllerHandles("ptsmc", ports, telemetry, notes, system=h.controller)


def uses_analytic_targets(scenario: Scenario) -> bool:
    """True unless a camera and an estimator are in the loop."""
    return scenario.measurement.estimator == "none"


def _baseline_handles(name: str, system, target: OutputPort, notes, model_based=False) -> ControllerHandles:
    """Baselines log their telemetry port (and the target they saw) at every step."""
    ports = {"telemetry": system.GetOutputPort("telemetry"), "target": target}
    layout = system.layout

    def telemetry(logs: dict) -> dict:
        out = {key: logs["telemetry"][:, part] for key, part in layout.items()}
        out |= _target_columns(logs["target"])
        return out

    return ControllerHandles(name, ports, telemetry, notes, model_based, system)


def _wire(builder, station_system, system, scenario) -> OutputPort:
    builder.Connect(station_system.GetOutputPort("state"), system.GetInputPort("state"))
    builder.Connect(system.GetOutputPort("u"), station_system.GetInputPort("actuation"))
    target = target_view(builder, station_system, scenario)
    builder.Connect(target, system.GetInputPort("target"))
    return target


def _common(station: Station, scenario: Scenario) -> dict:
    plant = station.plant
    return {"plant": plant, "frame": plant.GetFrameByName(scenario.robot.end_effector),
            "schedule": scenario.schedule()}


def _add_pd(builder, station_system, station: Station, scenario: Scenario) -> ControllerHandles:
    config = scenario.controller.pd
    system = builder.AddNamedSystem("pd", PDController(**_common(station, scenario), config=config))
    target = _wire(builder, station_system, system, scenario)
    notes = []
    for i, ic in enumerate(scenario.interceptions):
        g = config.gains_for(ic.tf)
        notes.append(f"pd segment {i}: Kp = {g['Kp']:.4g} N/m, Kd = {g['Kd']:.4g} N·s/m, "
                     f"Ki = {g['Ki']:.4g} N/(m·s) (triple pole at −{g['omega']:.3g} rad/s for "
                     f"{config.mass:g} kg)")
    return _baseline_handles("pd", system, target, notes)


def _add_smc(builder, station_system, station: Station, scenario: Scenario) -> ControllerHandles:
    config = SMCConfig.from_gains(gains_of(scenario), lambda_factor=scenario.controller.smc.lambda_factor)
    system = builder.AddNamedSystem("smc", FirstOrderSMC(**_common(station, scenario), config=config))
    target = _wire(builder, station_system, system, scenario)
    notes = [f"smc segment {i}: λ = {config.lambda_factor:g}/tf = {config.lambda_factor / ic.tf:.3g} 1/s, "
             f"K = {config.K:g}, Λ = {config.Lambda:g}" for i, ic in enumerate(scenario.interceptions)]
    return _baseline_handles("smc", system, target, notes)


def _add_ct_quintic(builder, station_system, station: Station, scenario: Scenario) -> ControllerHandles:
    """Model-based: the nominal model (the file's, without the scenario's plant deviations)
    and, for analytic targets, their exact future."""
    nominal = copy.deepcopy(scenario)
    nominal.plant = PlantConfig()
    predict = None
    if uses_analytic_targets(scenario):
        seen = controller_targets(scenario)

        def predict(i, t1, _target, seen=seen):
            return seen[i].evaluate(t1)[0:6]
    config = scenario.controller.ct_quintic
    system = builder.AddNamedSystem("ct_quintic", CtQuinticController(
        **_common(station, scenario), config=config, nominal_plant=make_plant(nominal), predict=predict))
    target = _wire(builder, station_system, system, scenario)
    notes = [f"ct_quintic: inverse dynamics of the nominal model, ω = {config.omega:g} rad/s, "
             f"target future {'exact (analytic)' if predict else 'extrapolated from the estimate'}"]
    return _baseline_handles("ct_quintic", system, target, notes, model_based=True)


_REGISTRY = {"ptsmc": _add_ptsmc, "pd": _add_pd, "smc": _add_smc, "ct_quintic": _add_ct_quintic}
CONTROLLERS = tuple(_REGISTRY)


def AddController(builder: DiagramBuilder, station_system, station: Station,
                  scenario: Scenario) -> ControllerHandles:
    """Add ``scenario.controller.type`` to ``builder`` and wire it to the station."""
    return _REGISTRY[scenario.controller.type](builder, station_system, station, scenario)
