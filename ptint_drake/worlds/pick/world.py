"""The pick-and-place world (``pick`` block): a gripper on the arm, parts on belts, a tray.

``PickWorld`` is the ``worlds.base.World`` of scenarios with a ``pick`` block: its checks
(``validate``), its schedule (``tasks.pick_plan``), its diagram (``run.build_pick``), its stops
(every segment's start and end and every close command), its metrics (``metrics.pick_metrics``:
the segments and ``picks``) and verdict (``metrics.pick_reasons``), its figure and replay
(``views``).  The runner (``worlds.runner``) simulates it.
"""

from __future__ import annotations

from pathlib import Path

from pydrake.common.yaml import yaml_load_typed

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.config.yaml_io import dump_yaml
from ptint_drake.mass_scaling import scale_in_context
from ptint_drake.metrics import Reason, drive_metrics
from ptint_drake.run_warnings import sampled_control_warnings
from ptint_drake.worlds.base import World, WorldRun
from ptint_drake.worlds.pick import studies
from ptint_drake.worlds.pick.clearance import arm_warnings, check_pick_clearance
from ptint_drake.worlds.pick.config import (DEFAULT_APPROXIMATION, SCENARIO_PLANT_FIELDS, check_pick_parts,
                                            check_plant_settings)
from ptint_drake.worlds.pick.metrics import pick_metrics, pick_reasons, segment_rows
from ptint_drake.worlds.pick.run import (build_pick, check_pick_plant, check_pick_reachable, pick_series,
                                         pick_simulator, segment_aims)
from ptint_drake.worlds.pick.tasks import check_tasks, pick_plan


class PickRun(WorldRun):
    """A pick scenario's diagram driven by the runner (``worlds.base.WorldRun``)."""

    advance_at_reached_stops = True  # the discrete plant's update at t = 0 before the first aims

    def __init__(self, scenario: Scenario):
        check_pick_plant(scenario)
        self.scenario = scenario
        self.built = build_pick(scenario)
        self.diagram, self.controller = self.built.diagram, self.built.controller
        self.simulator_config = pick_simulator(scenario)
        self.plant_time_step = self.built.station.config.time_step
        self._aims: dict = {}

    def pre_run_warnings(self) -> list[str]:
        check_pick_reachable(self.scenario, self.built)
        check_pick_clearance(self.scenario, self.built)  # the fingers clear of the belts
        return sampled_control_warnings(self.scenario) + arm_warnings(self.scenario, self.built)

    def initialize(self, context) -> None:
        station = self.built.station
        plant_context = station.plant.GetMyMutableContextFromRoot(context)
        scale_in_context(station.plant, plant_context, station.arm, self.scenario.plant.mass_scale)
        station.start_running(plant_context)

    def stops(self) -> list[float]:
        plan, duration = self.built.plan, self.scenario.duration
        stops = {duration, *plan.close_times}
        for seg in plan.schedule.segments:
            stops.update({seg.start, seg.end})
        return sorted(t for t in stops if 0.0 <= t <= duration)

    def at_stop(self, context, t: float) -> None:
        self._aims[t] = segment_aims(self.built, context)

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        built = self.built
        logs = {name: (logger.FindLog(context).sample_times().copy(), logger.FindLog(context).data().T.copy())
                for name, logger in built.loggers.items()}
        series = pick_series(built, logs)
        metrics = pick_metrics(self.scenario, built, logs, segment_rows(built, self._aims))
        metrics |= drive_metrics(built.plan.schedule, series["t"], series["tau"], series["tau_applied"],
                                 series["v"], built.limits)
        return metrics, series, []

    def sim_info(self, integrator) -> dict:
        config = self.built.station.config
        return {"contact_approximation": config.contact_approximation, "contact_model": config.contact_model}


class PickWorld(World):
    """Scenarios with a ``pick`` block (module docstring)."""

    name = "pick"
    block = "pick"
    summary = "pick and place: a gripper on the arm, parts on belts, a tray (docs/pick_place.md)"

    def validate(self, scenario: Scenario) -> None:
        """Segments come from ``pick.tasks`` (no ``interceptions``), grasped from above
        (``controller.task: top_down``) under sampled control; the world and the tasks
        (``config.check_pick_parts``, ``tasks.check_tasks``)."""
        s = scenario
        if s.interceptions:
            raise ScenarioError("interceptions: a pick scenario's segments come from pick.tasks; leave "
                                "interceptions out")
        if s.measurement is not None:
            raise ScenarioError("measurement: a pick scenario aims at the parts' simulated poses; a camera "
                                "is not modelled there (leave measurement out)")
        if s.controller.task != "top_down":
            raise ScenarioError(f"controller.task: a pick grasps from above: top_down, "
                                f"got {s.controller.task!r}")
        if not s.controller.control_period > 0.0:
            raise ScenarioError("controller.control_period: a pick runs on a discrete plant with contact and "
                                "needs sampled control: set it > 0 (e.g. 0.001)")
        if s.multibody is not None:
            m = s.multibody
            check_plant_settings(m.time_step, m.discrete_contact_approximation or DEFAULT_APPROXIMATION,
                                 m.contact_model, SCENARIO_PLANT_FIELDS)
        check_pick_parts(s.pick)
        check_tasks(s.pick)
        end = pick_plan(s.pick).end
        if s.duration < end:
            raise ScenarioError(f"duration: {s.duration:g} s ends before the pick tasks do ({end:.3g} s)")

    def schedule(self, scenario: Scenario):
        return pick_plan(scenario.pick).schedule

    def prepare(self, scenario: Scenario, log: bool = True) -> PickRun:
        return PickRun(scenario)

    def reasons(self, metrics: dict, criteria) -> list[Reason]:
        return [Reason(None, code, f"pick {k}: {code}") for k, code in pick_reasons(metrics["picks"])]

    def figure_files(self, scenario: Scenario) -> list[str]:
        return ["picks.png"]

    def view_tasks(self, scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        names = [n for n, on in (("pick_replay", replay), ("picks", figures)) if on]
        text = dump_yaml(scenario)  # picklable, for a worker process
        return [(n, series, metrics, stage, scenario.name, (text,)) for n in names]

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        from ptint_drake.worlds.pick.views import pick_figure, write_pick_replay  # noqa: PLC0415  (matplotlib)

        if name == "picks":
            pick_figure(series, metrics, stage / "picks.png")
        else:
            write_pick_replay(yaml_load_typed(schema=Scenario, data=args[0]), series, stage / "replay.html")
        return name

    def floor_diagram(self, scenario: Scenario, kind: str):
        """``"replay"``: the run beside its replayed-arm floor (``studies.FloorReplay``); no other kind."""
        return studies.FloorReplay(scenario, PickRun) if kind == "replay" else None

    def report(self, scenario: Scenario, metrics: dict, out) -> int:
        return studies.report(scenario, metrics, out)

    def tune_refusal(self, name: str) -> str:
        return (f"scenario: {name} is a pick and place, which tune does not search; tune the "
                f"interception of its parts instead (e.g. conveyor_yaw) and use those gains")

    def robust_sample(self, scenario: Scenario, name: str, seed: int, u) -> tuple:
        return studies.robust_sample(scenario, name, seed, u)

    def robust_row(self, seed: int, params: dict, metrics: dict) -> dict:
        return studies.robust_row(seed, params, metrics)

    def robust_summary(self, rows: list) -> dict:
        return studies.robust_summary(rows)

    def sweep_point(self, row: dict, scenario: Scenario, beta: float, tf: float, simulate, validate) -> dict:
        return studies.sweep_point(row, scenario, beta, tf, simulate, validate,
                                   lambda s: self.schedule(s).segments[-1].end)
