"""The interception world: an arm, and objects that move by a known law (the paper's setting).

``InterceptionWorld`` is the ``worlds.base.World`` of scenarios with ``interceptions``.  Its
diagram (``build``): the station (``station.MakeStation``: the plant, continuous unless
``multibody`` makes it discrete, with the scenario's deviations, the saturation, the true
objects) and the controller in its slot (``controllers.AddControllerTo``, through the drive's
zero-order hold when ``controller.control_period`` > 0), with per-integrator-step loggers of the
plant state and whatever the controller declares (the fused interceptor logs only its state
ports and recomputes its telemetry afterwards; logging adds no step-size cap).

The simulator stops at exactly every segment's start, start + tf/2 and start + tf (``stops``):
``AdvanceTo`` lands on those times, no log is interpolated.  The metrics (``metrics.run_metrics``)
use the gripper point computed from the logged plant state and the true objects — never the
controller's own view.  The divergence watchdog (``watchdog.Watchdog``) stops a run going nowhere.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.config.schema import Scenario
from ptint_drake.controllers import AddControllerTo, ControllerHandles, TargetView
from ptint_drake.robot.reachability import check_reachable
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET
from ptint_drake.systems.task.targets import active_target_values
from ptint_drake.verdict.metrics import Reason, run_metrics, segments_reasons
from ptint_drake.verdict.run_warnings import (joint_limit_warnings, sampled_control_warnings,
                                              singularity_warnings, torque_feasibility)
from ptint_drake.verdict.watchdog import Watchdog
from ptint_drake.views.derivatives import uniform_derivatives
from ptint_drake.worlds.base import World, WorldRun, arm_sample
from ptint_drake.worlds.interception import views
from ptint_drake.worlds.interception.checks import check_interceptions
from ptint_drake.worlds.interception.floors import floor_diagram
from ptint_drake.worlds.interception.objects import interception_schedule, interception_targets
from ptint_drake.worlds.interception.series import collect_series, orientation_series
from ptint_drake.worlds.interception.station import MakeStation, Station
from ptint_drake.worlds.stateless_derivatives import install_stateless_derivatives


@dataclass
class Built:
    """A built interception diagram and its handles."""

    diagram: object
    station: Station
    controller: ControllerHandles
    loggers: dict
    schedule: Schedule

    @property
    def plant(self):
        return self.station.plant


def AddController(builder: DiagramBuilder, station_system, station: Station, scenario: Scenario
                  ) -> ControllerHandles:
    """Add ``scenario.controller.type`` to ``builder`` and wire it to the station's ports
    (``controllers.AddControllerTo``), aiming at what ``TargetView`` lets it see."""
    plant, schedule = station.plant, interception_schedule(scenario)
    return AddControllerTo(builder, plant=plant, frame=plant.GetFrameByName(scenario.robot.end_effector),
                           schedule=schedule, state=station_system.GetOutputPort("state"),
                           actuation=station_system.GetInputPort("actuation"), scenario=scenario,
                           target=TargetView(builder, station_system, scenario, schedule,
                                             station.true_targets),
                           targets=station.true_targets)


def build(scenario: Scenario, log: bool = True) -> Built:
    """The scenario's diagram: the station, the controller in its slot, and (``log``)
    per-step loggers of the plant state and the controller's declared ports."""
    builder = DiagramBuilder()
    station = MakeStation(scenario)
    station_system = builder.AddSystem(station.diagram)
    controller = AddController(builder, station_system, station, scenario)
    loggers = {}
    if log:
        loggers["state"] = LogVectorOutput(station_system.GetOutputPort("state"), builder, publish_period=0.0)
        for name, port in controller.log_ports.items():
            loggers[name] = LogVectorOutput(port, builder, publish_period=0.0)
    diagram = builder.Build()
    diagram.set_name(scenario.name or "ptint")
    install_stateless_derivatives(diagram)  # Drake's nanobind bindings: ~10 µs per leaf saved
    return Built(diagram, station, controller, loggers, interception_schedule(scenario))


class InterceptionRun(WorldRun):
    """An interception scenario's diagram driven by the runner (``worlds.base.WorldRun``)."""

    def __init__(self, scenario: Scenario, log: bool = True):
        self.scenario = scenario
        self.built = built = build(scenario, log)
        self.diagram, self.controller = built.diagram, built.controller
        self.simulator_config = scenario.simulator
        self.plant_time_step = scenario.multibody.time_step if scenario.multibody is not None else 0.0
        plant = built.plant
        self.kinematics = FrameKinematics(plant, plant.GetFrameByName(scenario.robot.end_effector))
        self._nq = plant.num_positions()
        self._samples: dict = {}
        self._watchdog = None

    @property
    def station(self) -> Station:
        return self.built.station

    @property
    def plant(self):
        return self.built.plant

    @property
    def loggers(self) -> dict:
        return self.built.loggers

    @property
    def schedule(self) -> Schedule:
        return self.built.schedule

    def pre_run_warnings(self) -> list[str]:
        """Reachability (raises ScenarioError), torque feasibility and the control period."""
        plant, s, targets = self.built.plant, self.scenario, self.built.station.true_targets
        check_reachable(plant, s, self.built.schedule, targets)
        return torque_feasibility(plant, s, targets) + sampled_control_warnings(s)

    def gripper(self, context):
        """(x, ẋ, J) of the gripper point from the plant state in the root ``context``."""
        plant = self.built.plant
        qv = plant.get_state_output_port().Eval(plant.GetMyContextFromRoot(context))
        return self.kinematics.compute(qv[:self._nq], qv[self._nq:])

    def true_state(self, t: float):
        """The true [x_r, ẋ_r, ẍ_r] of the segment active at ``t``."""
        return active_target_values(self.built.schedule, self.built.station.true_targets, t)

    def monitor(self, progress):
        self._watchdog = Watchdog(scenario=self.scenario, diagram=self.diagram, plant=self.built.plant,
                                  position_of=lambda c: self.gripper(c)[0],
                                  true_target=lambda t: self.true_state(t)[TARGET.x], progress=progress)
        return self._watchdog

    def watchdog_failure(self):
        return self._watchdog.failure if self._watchdog is not None else None

    def stops(self) -> list[float]:
        stops = {self.scenario.duration}
        for seg in self.built.schedule.segments:
            stops.update({seg.start, seg.start + 0.5 * seg.tf, seg.end})
        return sorted(stops)

    def at_stop(self, context, t: float) -> None:
        x, xdot, _ = self.gripper(context)
        target = self.true_state(t)
        self._samples[t] = (x - target[TARGET.x], xdot - target[TARGET.xdot])
        if self._watchdog is not None and any(seg.start == t for seg in self.built.schedule.segments):
            self._watchdog.segment_started(np.linalg.norm(self._samples[t][0]))

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        s, built = self.scenario, self.built
        series = collect_series(built, context, self.kinematics)
        if s.controller.task != "position":
            series |= orientation_series(s.controller.task, self.kinematics, series,
                                         built.station.true_targets,
                                         built.schedule, s.duration)
        metrics = run_metrics(s, built.schedule, self._samples, series, built.station.effort_limits)
        warnings = singularity_warnings(s, series) + joint_limit_warnings(built.plant, series)
        return metrics, series, warnings

    def sim_info(self, integrator) -> dict:
        s = self.scenario
        return {"integration_scheme": s.simulator.integration_scheme, "accuracy": s.simulator.accuracy,
                "switching": s.controller.switching, "implementation": s.controller.implementation,
                "derivative_evaluations": int(integrator.get_num_derivative_evaluations())}


class InterceptionWorld(World):
    """Scenarios with ``interceptions`` (module docstring)."""

    name = "interception"
    block = None
    summary = "an arm intercepting objects that move by a known law (the paper's setting)"

    def validate(self, scenario: Scenario) -> None:
        check_interceptions(scenario)

    def schedule(self, scenario: Scenario) -> Schedule:
        return interception_schedule(scenario)

    def objects(self, scenario: Scenario) -> list:
        return interception_targets(scenario)

    def prepare(self, scenario: Scenario, log: bool = True) -> InterceptionRun:
        return InterceptionRun(scenario, log)

    def reasons(self, metrics: dict, criteria) -> list[Reason]:
        return segments_reasons(metrics, criteria)

    def figure_files(self, scenario: Scenario) -> list[str]:
        from ptint_drake.views.plots import run_figure_stems  # noqa: PLC0415  (no matplotlib import)

        return [f"{s}.png" for s in run_figure_stems(scenario.controller.task)]

    def view_tasks(self, scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        return views.view_tasks(scenario, interception_targets(scenario), series, metrics, stage, figures,
                                replay, svg)

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        return views.draw_view(name, series, metrics, stage, title, args)

    def tune_refusal(self, name: str) -> None:
        return None  # tune searches this world's segment verdicts

    def robust_sample(self, scenario: Scenario, name: str, seed: int, u) -> tuple:
        """The arm's deviations (``arm_sample``), then the camera's noise std and latency: the
        scenario's camera, or an ``auto`` one when either range is above 0 (else the analytic
        target, the paper's setting)."""
        scenario, params = arm_sample(scenario, name, seed, u)
        m = scenario.measurement
        if max(u.bounds("noise")) > 0.0 or max(u.bounds("latency")) > 0.0:
            if m is None or m.estimator == "none":
                scenario.measurement = m = MeasurementConfig()
        noise, latency = float(u("noise")), float(u("latency"))
        if m is not None:
            m.noise_std, m.latency, m.seed = noise, latency, int(seed)
        return scenario, params | {"noise_std": noise, "latency": latency}

    def sweep_point(self, row: dict, scenario: Scenario, beta: float, tf: float, simulate, validate) -> dict:
        """Every interception's β and tf set (the duration long enough for the last one's hold),
        simulated; ``row`` gets the extremes over the segments (``studies.sweep.COLUMNS``)."""
        for ic in scenario.interceptions:
            ic.beta, ic.tf = beta, tf
        last = scenario.interceptions[-1]
        scenario.duration = max(scenario.duration, last.start + 2.0 * tf)
        validate(scenario)
        result = simulate(scenario)
        m = result.metrics
        segs = m["segments"]
        _, _, _, jerk = uniform_derivatives(result.series["t"], result.series["xdot"])
        row.update({
            "e0": max(s["e0_norm"] for s in segs),
            "e_tf": max(s["e_tf_norm"] for s in segs),
            "e_half": min(s["e_half_norm"] for s in segs),
            "hold": max(s["e_hold_max_norm"] for s in segs),
            "peak_torque": float(np.max(m["torque_peak"])),
            "peak_torque_after_startup": float(np.max(m["torque_peak_after_startup"])),
            "peak_jerk": float(np.max(np.linalg.norm(jerk, axis=1))),
            "realtime_factor": m["sim"]["realtime_factor"],
            "steps": m["sim"]["steps"],
            "ok": m["status"] == "ok",  # the one verdict (metrics.verdict, the scenario's criteria)
        })
        return row

    def floor_diagram(self, scenario: Scenario, kind: str):
        if kind == "controller":
            return InterceptionRun(scenario, log=False)
        return floor_diagram(scenario, kind, interception_schedule(scenario))


__all__ = ["AddController", "Built", "InterceptionRun", "InterceptionWorld", "build"]
