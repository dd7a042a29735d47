"""The pick-and-place world (``pick`` block): a gripper on the arm, parts on belts, a tray.

``PickWorld`` is the ``worlds.base.World`` of scenarios with a ``pick`` block: its checks
(``validate``), its schedule (``tasks.pick_plan``), its diagram (``run.build_pick``), its stops
(every segment's start and end and every close command), its metrics (``metrics.pick_metrics``:
the segments and ``picks``) and verdict (``metrics.pick_reasons``), its figure and replay
(``views``).  The runner (``worlds.runner``) simulates it.

The confirmed grasp: every ``SENSE_PERIOD`` from a close command (``empty`` or ``lost`` act at once) and
at each task's check (its lift's planned start, prescribed grasp time + ``dwell``) ``PickRun.at_stop``
reads the ``GraspObserver``'s state (what the gripper senses). ``holding``: the plan goes on.  ``closing``
(still moving): the lift waits, ``GRASP_WAIT`` at a time, up to ``pick.grasp_window`` after the prescribed
grasp time.  ``empty``, ``lost``, or the window over: while ``pick.retries`` allow, a retry is planned
from that moment and the part's current (simulated) pose — a backoff (up ``clearance``, the fingers
opening), a new approach and descend, then the task's lift, carry, place and retreat, later tasks shifted
— if its grasp and lift points (the part's position extrapolated at its current velocity to the new grasp
time) are reachable from above; otherwise (``refused``) the arm backs off the same way, fingers open, and
the task goes on with an empty hand (``tasks.Replan.abort``).  A new plan means a new diagram (the
controller's schedule is built into it): ``replan`` builds it and ``resume`` carries the numeric state
(time, plant, controller, drive, observer, targets) into its context; the runner goes on from there.  If
the retries push the plan's end later, the run is lengthened by as much (metrics ``duration``).

A line (``pick.line``, issue 44): ``line.driver`` makes its pool of parts, acts for the truth side
and decides its tasks at the stops (``NoLine``, without a line: the same hooks, doing nothing); its
truth ends the run before the duration (a cap) once the line is done (``line.truth.run_end``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
from pydrake.common.yaml import yaml_load_typed

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.config.yaml_io import dump_yaml
from ptint_drake.robot.mass_scaling import scale_in_context
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.hand.gripper import CLOSING, GRASP_STATES, HOLDING
from ptint_drake.verdict.metrics import Reason, drive_metrics
from ptint_drake.verdict.run_warnings import joint_limit_warnings, sampled_control_warnings
from ptint_drake.worlds.base import LinkPorts, World, WorldRun
from ptint_drake.worlds.pick import studies
from ptint_drake.worlds.pick.camera import MIN_FITS, check_pick_camera, estimate_metrics
from ptint_drake.worlds.pick.clearance import arm_warnings, check_pick_clearance
from ptint_drake.worlds.pick.config import (DEFAULT_APPROXIMATION, SCENARIO_PLANT_FIELDS, check_pick_parts,
                                            check_plant_settings)
from ptint_drake.worlds.pick.controller_side import pick_link_ports, plan_stands
from ptint_drake.worlds.pick.grasp_gate import grasp_refusal
from ptint_drake.worlds.pick.line.checks import check_line_scenario, line_plan, line_warnings
from ptint_drake.worlds.pick.line.driver import LineDriver, NoLine, view_scenario
from ptint_drake.worlds.pick.line.metrics import line_reasons, placed_collision_warnings
from ptint_drake.worlds.pick.metrics import pick_metrics, pick_reasons, segment_rows
from ptint_drake.worlds.pick.placement import bridging_warnings, check_placement
from ptint_drake.worlds.pick.route import routed_plan
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.run import (build_pick, check_pick_plant, check_pick_reachable, pick_logs,
                                         pick_series, pick_simulator, segment_aims)
from ptint_drake.worlds.pick.runaway import runaway_metrics
from ptint_drake.worlds.pick.tasks import Replan, check_tasks, pick_plan

GRASP_WAIT = 0.05  # s, the lift's wait for ``holding`` while the fingers are still closing
SENSE_PERIOD = 0.01  # s, between the reads of the grasp state from a close command to its check


class PickRun(WorldRun):
    """A pick scenario's diagram driven by the runner (``worlds.base.WorldRun``)."""

    advance_at_reached_stops = True  # the discrete plant's update at t = 0 before the first aims

    def __init__(self, scenario: Scenario):
        check_pick_plant(scenario)
        # a line (issue 44): its pool of parts and the decisions it makes (``line.driver``)
        self.line = LineDriver(scenario) if scenario.pick.line is not None else NoLine(scenario)
        self.scenario = scenario = self.line.scenario
        self.built = build_pick(scenario)
        self.line.bind(self.built)
        self.diagram, self.controller = self.built.diagram, self.built.controller
        self.simulator_config = pick_simulator(scenario)
        self.plant_time_step = self.built.station.config.time_step
        self._aims: dict = {}
        n = len(scenario.pick.tasks)
        self.replans = [Replan() for _ in range(n)]
        self.checks: list[list[dict]] = [[] for _ in range(n)]  # per task, attempt: {state, t} at the check
        self.refused: list = [None] * n  # why a retry was not planned (out of reach / of retries)
        self.estimates: dict = {}  # with a camera, per task: the estimate at the grasp and the truth
        self.end = self.cap = scenario.duration  # (a line's run may end earlier: ``at_stop``)
        self._tail = 0.0 if self.line.active else scenario.duration - self.built.plan.end  # (a line's end)
        self._pieces: list = []  # the logs of the diagrams a replan replaced
        self._rebuilt = False

    def pre_run_warnings(self) -> list[str]:
        if self.line.active:
            return sampled_control_warnings(self.scenario) + line_warnings(self.scenario, self.line)
        check_pick_reachable(self.scenario, self.built)
        check_pick_clearance(self.scenario, self.built)  # the fingers clear of the belts
        return (sampled_control_warnings(self.scenario) + arm_warnings(self.scenario, self.built)
                + bridging_warnings(self.scenario.pick))

    def initialize(self, context) -> None:
        station = self.built.station
        plant_context = station.plant.GetMyMutableContextFromRoot(context)
        scale_in_context(station.plant, plant_context, station.arm, self.scenario.plant.mass_scale)
        station.start_running(plant_context)
        self.line.start(context)

    def _sense_times(self, k: int) -> list[float]:
        """The reads of task k's grasp state between its last close command and its check (on the
        plant's step grid), if that check is still to come."""
        attempts, dt = self.built.plan.attempts[k], self.plant_time_step
        if len(self.checks[k]) >= len(attempts):
            return []
        a = attempts[-1]
        n = int((a.check - a.close) / SENSE_PERIOD)
        return [round((a.close + j * SENSE_PERIOD) / dt) * dt for j in range(1, n + 1)]

    def stops(self) -> list[float]:
        plan, duration = self.built.plan, self.end
        stops = {duration, *plan.close_times, *(a.check for task in plan.attempts for a in task)}
        for k in range(len(plan.attempts)):
            stops.update(self._sense_times(k))
        for seg in plan.schedule.segments:
            stops.update({seg.start, seg.end})
        stops.update(self.line.stops(duration))
        return sorted(t for t in stops if 0.0 <= t <= duration)

    def at_stop(self, context, t: float) -> None:
        self._aims[t] = segment_aims(self.built, context)
        if self.built.estimates is not None:
            self._record_estimate(context, t)
        for k, attempts in enumerate(self.built.plan.attempts):
            if len(self.checks[k]) >= len(attempts):
                continue
            if self.built.estimates is not None and self._unseen(context, k, t):
                continue
            if abs(attempts[-1].check - t) < 1e-9:
                self._check(context, k, t, self._grasp_state(context))
            elif any(abs(s - t) < 1e-12 for s in self._sense_times(k)):
                state = self._grasp_state(context)
                if not plan_stands(state, "sense"):  # nothing between the fingers: no need to wait
                    self._check(context, k, t, state)
        self._rebuilt |= self.line.at_stop(self, context, t)  # a line's decision: a new task
        if self.line.active:  # a line done ends the run before its cap (``line.truth.run_end``)
            self.end = self.line.truth.run_end(context, t, self._rebuilt, self.built.plan.end, self.cap)

    def _unseen(self, context, k: int, t: float) -> bool:
        """With a camera, at task k's descend start: if the part was never seen — or fitted fewer
        than ``camera.MIN_FITS`` times, too few for a velocity to aim at — or the open fingers
        would not fit beside a neighbour (``grasp_gate``), no grasp: the task backs off at once
        (no close command) and its check reads ``part not seen`` or ``blocked``.  True when it did."""
        plan = self.built.plan
        i = plan.segment_index(k, "descend")
        last = plan.segments[i].attempt == len(plan.attempts[k]) - 1
        if not last or abs(plan.schedule.segments[i].start - t) > 1e-9:
            return False
        why = grasp_refusal(self.built, context, k, plan.segments[i].index, t, MIN_FITS,
                            self.scenario.pick.tasks[k].margin)
        if why is None:
            return False
        self.refused[k] = why[0]
        self.checks[k].append(why[1])
        self.replans[k] = Replan(self.replans[k].retries, 0.0, abort=t)
        self._rebuild()
        return True

    def _record_estimate(self, context, t: float) -> None:
        """With a camera, at a task's prescribed grasp: the estimate the grasp latches and the truth."""
        plan = self.built.plan
        for k, grasp in enumerate(plan.grasp_times):
            if abs(grasp - t) > 1e-9:
                continue
            part = plan.segments[plan.segment_index(k, "approach")].index
            station = self.built.diagram.GetSubsystemByName("pick_station")
            sc = station.GetMyContextFromRoot(context)
            parts = self.built.estimates.parts
            pc = parts.GetMyContextFromRoot(context)
            self.estimates[k] = {name: port.Eval(c)[:size].copy() for name, port, c, size in (
                ("true", station.GetOutputPort(f"part_{part}_pose"), sc, 3),
                ("true_R", station.GetOutputPort(f"part_{part}_rotation"), sc, 9),
                ("estimate", parts.GetOutputPort(f"part_{part}_pose"), pc, 3),
                ("estimate_R", parts.GetOutputPort(f"part_{part}_rotation"), pc, 9))}

    def _grasp_state(self, context) -> int:
        observer = self.built.observer
        return int(observer.GetOutputPort("grasp_state").Eval(observer.GetMyContextFromRoot(context))[0])

    def _check(self, context, k: int, t: float, state: int) -> None:
        """The grasp check of task k's last attempt (module docstring): may set a new plan."""
        built, pick = self.built, self.scenario.pick
        attempt = built.plan.attempts[k][-1]
        replan = self.replans[k]
        if state == CLOSING and t + GRASP_WAIT <= attempt.grasp + pick.grasp_window + 1e-9:
            self.replans[k] = Replan(replan.retries, replan.lift_delay + GRASP_WAIT)
            self._rebuild()
            return
        self.checks[k].append({"state": GRASP_STATES[state], "t": t})
        if state == HOLDING:
            return
        candidate = self.replans.copy()
        candidate[k] = Replan(replan.retries + (t,), 0.0)
        if len(replan.retries) >= pick.retries:
            why = "out of retries"
        else:
            why = self._unreachable(context, k, pick_plan(pick, tuple(candidate)).attempts[k][-1].grasp, t)
        if why:  # no retry: back off with the fingers open, then the rest of the task
            self.refused[k] = why
            candidate[k] = Replan(replan.retries, 0.0, abort=t)
        self.replans = candidate
        self._rebuild()

    def _unreachable(self, context, k: int, grasp: float, t: float):
        """Why the retry of task k grasping at ``grasp`` cannot be made, or None."""
        built, task = self.built, self.scenario.pick.tasks[k]
        part = [p.name for p in built.station.config.parts].index(task.part)
        station = built.diagram.GetSubsystemByName("pick_station")
        sc = station.GetMyContextFromRoot(context)
        source = built.part_system()  # the estimate with a camera
        pose = source.GetOutputPort(f"part_{part}_pose").Eval(source.GetMyContextFromRoot(context))
        q = station.GetOutputPort("state").Eval(sc)[:built.arm.num_positions()]
        x = pose[0:3] + pose[3:6] * (grasp - t)
        frame = built.arm.GetFrameByName(self.scenario.robot.end_effector)
        for where in (x, x + [0.0, 0.0, task.lift_height]):
            if inverse_kinematics(built.arm, frame, np.asarray(where), q, down=True) is None:
                return f"out of reach ({np.round(where, 3).tolist()} m)"
        return None

    def _rebuild(self) -> None:
        self._rebuilt = True

    def replan(self, context, t: float) -> bool:
        """After ``at_stop``: True when the check planned anew (a new diagram to resume into)."""
        if not self._rebuilt:
            return False
        self._rebuilt = False
        self._pieces.append(pick_logs(self.built, context))  # the old diagram's loggers, up to now
        self.built = build_pick(self.scenario, tuple(self.replans), self.line.planning())
        self.diagram, self.controller = self.built.diagram, self.built.controller
        self.line.bind(self.built)
        self.end = self.cap = max(self.scenario.duration, self.built.plan.end + self._tail)
        return True

    def resume(self, new_context, old_context) -> None:
        """Carry the time, the numeric state (plant, controller, drive, observer, targets: every
        continuous and discrete state) and set the arm's mass scale as ``initialize`` does.  Not
        carried: the plant's abstract state (its last step's contact results, holding the old
        diagram's geometry ids, which its next step computes anew)."""
        new_context.SetTime(old_context.get_time())
        new_context.SetContinuousState(old_context.get_continuous_state_vector().CopyToVector())
        for i in range(old_context.num_discrete_state_groups()):
            new_context.SetDiscreteState(i, old_context.get_discrete_state(i).value())
        station = self.built.station
        scale_in_context(station.plant, station.plant.GetMyMutableContextFromRoot(new_context), station.arm,
                         self.scenario.plant.mass_scale)
        for targets in (self.built.targets, self.built.true_targets):
            if targets is None:
                continue
            tc = targets.GetMyMutableContextFromRoot(new_context)
            value = targets.latch_value(tc)
            if value is not None:  # the backoff's latch, before the controller captures its start
                tc.SetDiscreteState(0, value)
        self.line.restore(new_context)  # a line's parked parts' locks and belt drives (parameters)

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        built = self.built
        logs = pick_logs(built, context)
        for name in logs:  # the pieces of the replaced diagrams, each up to where the next began
            t, data = logs[name]
            for t_piece, data_piece in reversed([piece[name] for piece in self._pieces]):
                keep = t_piece < (t[0] if len(t) else np.inf)
                t, data = np.concatenate([t_piece[keep], t]), np.concatenate([data_piece[keep], data])
            logs[name] = (t, data)
        series = pick_series(built, logs)
        metrics = pick_metrics(self.scenario, built, logs, segment_rows(built, self._aims),
                               {"checks": self.checks, "refused": self.refused, "end": self.end})
        estimate_metrics(self.scenario, metrics["picks"], self.estimates)
        metrics |= drive_metrics(built.plan.schedule, series["t"], series["tau"], series["tau_applied"],
                                 series["v"], built.limits)
        runaway_metrics(built, metrics, series)  # per pick: saturated, joint speed beyond limit
        self.line.add_metrics(metrics, series)  # a line's ``line`` (``line.metrics``)
        return metrics, series, joint_limit_warnings(built.arm, series) + placed_collision_warnings(metrics)

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
        if s.measurement is not None and s.measurement.sensor != "rgbd":
            raise ScenarioError("measurement.sensor: a pick scenario sees its parts through an rgbd camera "
                                "(sensor: rgbd) or aims at their simulated poses (leave measurement out)")
        if s.pick.line is not None:  # a line: its own checks (no parts, no tasks: it makes them)
            check_line_scenario(s)
            return
        check_placement(s.pick, s.measurement)  # random placement needs the camera
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
        check_pick_camera(s)  # the parts in the camera's view (nothing to see: rejected)
        end = pick_plan(s.pick).end
        if s.duration < end:
            raise ScenarioError(f"duration: {s.duration:g} s ends before the pick tasks do ({end:.3g} s)")

    def schedule(self, scenario: Scenario):
        # with its vias (route), as the run's; a line's: its idle segment (the run decides the rest)
        return (line_plan if scenario.pick.line is not None else routed_plan)(scenario).schedule

    def prepare(self, scenario: Scenario, log: bool = True) -> PickRun:
        return PickRun(scenario)

    def reasons(self, metrics: dict, criteria) -> list[Reason]:
        if "line" in metrics:  # a line: per part that entered and was not placed (``line.metrics``)
            return line_reasons(metrics["line"])
        return [Reason(None, code, f"pick {k}: {code}") for k, code in pick_reasons(metrics["picks"])]

    def figure_files(self, scenario: Scenario) -> list[str]:
        return ["picks.png", "timeline.png"] + (["estimates.png"] if _has_camera(scenario) else [])

    def view_tasks(self, scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        camera = figures and _has_camera(scenario)  # the estimates' figure and the camera's frames
        names = [n for n, on in (("pick_replay", replay), ("picks", figures), ("timeline", figures),
                                 ("estimates", camera), ("camera_frames", camera)) if on]
        text = dump_yaml(view_scenario(scenario))  # picklable, for a worker process (a line's: its pool)
        return [(n, series, metrics, stage, scenario.name, (text,)) for n in names]

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        from ptint_drake.worlds.pick.views import draw_pick_view  # noqa: PLC0415

        scenario = yaml_load_typed(schema=Scenario, data=args[0])
        return draw_pick_view(name, scenario, series, metrics, stage, title)

    def simulator_config(self, scenario: Scenario):
        return pick_simulator(scenario)

    def own_plant_step(self, scenario: Scenario) -> Optional[float]:
        """The station's plant step (``pick.time_step``) unless ``multibody`` sets it."""
        return world_config(scenario).time_step if scenario.multibody is None else None

    def link_ports(self, scenario: Scenario) -> LinkPorts:
        """The gripper, and the part tracker's reports or the camera's frames (``controller_side``)."""
        return pick_link_ports(scenario)

    def controller_side(self, builder, scenario: Scenario, period: float):
        """The targets, gripper sequence and grasp observer (``controller_side``)."""
        from ptint_drake.worlds.pick.controller_side import AddPickControllerSide  # noqa: PLC0415

        return AddPickControllerSide(builder, scenario, period, SENSE_PERIOD)

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


def _has_camera(scenario: Scenario) -> bool:
    return scenario.pick.line is None and getattr(scenario.measurement, "sensor", "") == "rgbd"  # (no line)
