"""The line's run (issue 44): the truth side's acts and the controller side's decisions at the
pick run's stops (``world.PickRun`` calls ``LineDriver``).

At every stop, first the truth (``truth.LineTruth``: releases, speed steps, parts past the end,
the slabs), then the controller side, from what it reads (``view.LineView``: the tracks, the known
belt speeds, the reach windows; the arm's state; its own tasks):

- **when the arm is free** (the idle segment over and the last task's retreat ended) the
  scheduler (``scheduler.decide``) chooses; the choice's grasp and lift points are checked again
  by IK from the arm's present posture, and the task (a ``PickTaskConfig`` with the tasks'
  defaults, ``start`` = its grasp time − the default approach and descend) is appended and the
  diagram rebuilt (the pick run's replan and resume).  A task whose cycle would end after the
  scenario's end is not started;
- **while a task approaches** (before its descend), ``watch`` compares the grasp point predicted
  now with the committed one and, beyond ``line.redecide_mm``, keeps the task, replaces it or
  gives it up (``watch``'s docstring).

Every chosen task is fitted to the plan the run will follow (``_fit``): a phase the plan splits by
a via gets what the via's two legs need (``line.cycle.LineCycles.detours``, ``via_split``), its
grasp later where the approach is stretched, and the task is not started where that grasp leaves
reach.

Every decision goes to the log (``decisions``: metrics.json ``line.decisions``); looks that find
nothing new are not repeated in it.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.systems.task.orientation import tool_yaw
from ptint_drake.worlds.pick.grasp_gate import finger_extent
from ptint_drake.worlds.pick.line.arrivals import close_delay, line_scenario
from ptint_drake.worlds.pick.line.cycle import LineCycles, estimate, kind_part
from ptint_drake.worlds.pick.phase_time import NoTfFits, held_mass
from ptint_drake.worlds.pick.line.grip import grip_axis, in_tray, logged
from ptint_drake.worlds.pick.line.metrics import line_metrics
from ptint_drake.worlds.pick.line.no_line import NoLine
from ptint_drake.worlds.pick.out_belt import OutPlace
from ptint_drake.worlds.pick.scene import bin_spots
from ptint_drake.worlds.pick.line.plan import IDLE_TF, line_plan, unpinned
from ptint_drake.worlds.pick.line.scheduler import Timing, blocker, decide
from ptint_drake.worlds.pick.line.truth import LineTruth
from ptint_drake.worlds.pick.line.slot_choice import choose, nearest
from ptint_drake.worlds.pick.line.via_split import DETOUR_PASSES, fitted
from ptint_drake.worlds.pick.line.view import LineView
from ptint_drake.worlds.pick.line.watch import watch
from ptint_drake.worlds.pick.scene import belt_frame
from ptint_drake.worlds.pick.tasks import Replan

__all__ = ["FAR_UPSTREAM", "LineDriver", "NoLine", "cycle_time", "view_scenario"]  # (NoLine: world's)

FAR_UPSTREAM = -1000.0  # m along its belt: where the plan's model puts a part it does not see


def cycle_time(task: PickTaskConfig) -> float:
    """s, one pick's planned cycle with the tasks' defaults: the six phases and two dwells."""
    phases = (task.approach, task.descend, task.lift, task.carry, task.place, task.retreat)
    return sum(m.tf for m in phases) + 2.0 * task.dwell


def view_scenario(scenario):
    """What a run's views draw: a line scenario as the pick scenario of its pool (no ``line``, no
    tasks: the replay's plant holds every pool part, the timeline a row per part); else itself."""
    if scenario.pick.line is None:
        return scenario
    expanded, _ = line_scenario(scenario)
    expanded.pick.line = None
    return expanded


class LineDriver:
    """A line run's truth and decisions (module docstring); ``scenario``: the line scenario, of
    which ``self.scenario`` is the expanded copy the run builds from (``arrivals.line_scenario``)."""

    active = True

    def __init__(self, scenario):
        self.scenario, self.releases = line_scenario(scenario)
        self.line = scenario.pick.line
        self.view = LineView(self.scenario)
        self.truth = None
        self.decisions: list = []  # the decision log
        self.replaced: list = []  # {"t", "task", "drift_mm"} of every task replaced in its approach
        self.committed: dict = {}  # task → [track, grasp time, point]
        self.timing = None
        self._last_look = None
        self._beliefs: dict = {}  # part → (offset, lateral, yaw_deg) as tracked at the last decision
        self._speeds: dict = {}  # belt → its known speed then
        self.cycles = None  # the min-tf model (``line.cycle``), built at the first bind
        self.planning_s: list = []  # wall s of each decision that chose (the scheduler and the model)
        self._vias: dict = {}
        self.given_up: set = set()  # tracks whose task was abandoned (``give_up``): not chosen again
        self.abandoned: list = []  # {"t", "task", "drift_mm"} of every task given up in its approach
        self.straight: dict = {}  # task → the model's tf of each of its phases (a kept task: ``watch``)

    def bind(self, built) -> None:
        """The (re)built diagram's handles."""
        if self.truth is None:
            self.truth = LineTruth(built.station, self.releases, self.line.speed_steps)
            task = PickTaskConfig()
            self.timing = Timing(lead=task.approach.tf + task.descend.tf, margin=task.margin,
                                 finger=finger_extent(built.station))
            self.cycles = LineCycles(self.scenario, window_at=self.view.window_at,  # (outbelt46: out_belt)
                                     finger=self.timing.finger)
        self.truth.rebind(built.station)
        self.view.bind(built)
        self.built = built

    def start(self, context) -> None:
        """At t = 0: the pool parked (``truth``)."""
        self.truth.start(context)

    def restore(self, context) -> None:
        """In a rebuilt diagram's context: the parameters a replan does not carry (``truth``)."""
        self.truth.restore(context)

    def planning(self):
        """The scenario the plan is made from (``run.build_pick``): the expanded one with every
        part where the controller side last saw it at a decision — its tracked position and yaw,
        riding its belt at the known speed (an ``offset`` that puts it there at that time) — and
        every part it never saw far upstream, so that the plan's vias (``obstacles``: the planning
        model holds the parts riding their belts) go over the parts that are there, and each
        task's approach is checked towards where its part was seen."""
        pick = self.scenario.pick
        far = {"offset": FAR_UPSTREAM, "lateral": 0.0}
        slots = self.view.slots_of(self._beliefs)  # the sensor's ids; a camera's tracks: their slots
        beliefs = {slots[i]: b for i, b in self._beliefs.items() if i in slots}
        parts = [replace(p, **(dict(zip(("offset", "lateral", "yaw_deg", "shape", "size"), beliefs[k]))
                               if k in beliefs else far)) for k, p in enumerate(pick.parts)]
        belts = [replace(b, speed=self._speeds.get(b.name, b.speed)) for b in pick.belts]
        return replace(self.scenario, pick=replace(pick, parts=parts, belts=belts))

    def _believe(self, tracks: list, t: float) -> None:
        """The tracked parts' places for ``planning`` (at time ``t``); a part no longer tracked
        (picked, or gone) keeps where it was last seen — its task's approach is planned to it."""
        for tr in tracks:
            belt = next(b for b in self.scenario.pick.belts if b.name == tr.belt)
            lateral = float(belt_frame(belt).inverse().multiply(np.asarray(tr.position))[1])
            yaw = float(np.degrees(np.arctan2(tr.axis[1], tr.axis[0])))  # world (``scene.part_start_pose``)
            kind = self.line.kind(tr.kind)  # (a camera's: as classified)
            self._beliefs[tr.id] = (tr.s - tr.speed * t, lateral, yaw, kind.shape, list(kind.size))
            self._speeds[tr.belt] = tr.speed

    def add_metrics(self, metrics: dict, series: dict) -> None:
        """metrics.json ``line`` (``metrics.line_metrics``) and the min-tf model's capacity estimate
        (``line.cycle.estimate``: ``capacity_estimate``, picks per minute and the cycle, s; None
        for both, and ``why_not``, where the model finds no cycle)."""
        metrics["line"] = line_metrics(self.scenario, self, metrics, series)
        try:
            ppm, cycle = estimate(self.scenario, self.view.window_at, self.cycles.model)
        except NoTfFits as error:  # (warned before the run, ``checks.line_warnings``)
            metrics["line"]["capacity_estimate"] = {"picks_per_minute": None, "cycle_s": None,
                                                    "why_not": str(error)}
            return
        metrics["line"]["capacity_estimate"] = {"picks_per_minute": ppm, "cycle_s": cycle}

    def stops(self, duration: float) -> list[float]:
        """The truth's stops and the scheduler's looks (every ``decide_period``)."""
        looks = np.arange(IDLE_TF, duration, self.line.decide_period).round(9)
        return sorted(set(self.truth.stops(duration)) | set(looks.tolist()))

    def at_stop(self, run, context, t: float) -> bool:
        """The truth's acts, then a decision if one is due; True when the tasks changed."""
        self.truth.at_stop(context, t)
        if t < IDLE_TF - 1e-9:
            return False
        if t < run.built.plan.end - 1e-9:  # a task (or a hold: ``give_up``) under way
            return bool(self.scenario.pick.tasks) and watch(self, run, context, t)
        return self._choose(run, context, t)

    def _choose(self, run, context, t: float, replacing=None) -> bool:
        """A decision from now, each track's lead from the min-tf model (``line.cycle``); a task
        appended (or task ``replacing`` replaced): True."""
        clock = time.perf_counter()
        tasks = self.scenario.pick.tasks
        tracks = self.view.tracks(context, t)
        windows = {tr.id: self.view.window(tr) for tr in tracks}
        keep = [k for k in range(len(tasks)) if k != replacing]
        assigned = {self.committed[k][0] for k in keep} | self.given_up
        used = {tasks[k].slot for k in keep}
        free = {c.name: [c.bin] if c.bin else [OutPlace(c.belt)] if c.belt  # (outbelt46: an outgoing belt)
                else [j for j in c.slots if j not in used] for c in self.line.catalog}
        q = self._arm_q(context)
        start, yaw = self._tool_now(q)  # the arm's present point and yaw
        decision = decide(t, tracks, windows, assigned, free, self.timing,
                          lambda tr, w: self.cycles.lead(tr, w, t, start, yaw),
                          lambda tr: self.cycles.axis(tr, windows[tr.id], start, yaw))
        cycle = None
        if decision.track is not None:
            if self.view.reachable(np.asarray(decision.point), q) is None:
                decision.skipped.append((decision.track, "out of reach by IK at the grasp"))
                decision.track = decision.grasp = decision.slot = decision.point = None
            else:
                cycle = self._cycle(decision, tracks, windows, t, start, yaw, free, keep)
                if cycle is None:
                    return False
                if decision.grasp - cycle.phases["descend"] + cycle.total - cycle.phases["approach"] \
                        > self.scenario.duration:
                    return False  # its cycle would end after the line's
        record = decision.record()
        if decision.track is None:
            look = [(s["track"], s["reason"]) for s in record["skipped"]]
            if look and look != self._last_look:
                self.decisions.append(record)
            self._last_look = look
            return False
        self._last_look = None
        part = self._part_of(context, decision.track, tracks)
        self._believe(tracks, t)
        task = self._fit(run, t, decision, replacing, cycle, tracks, part)
        if task is None:
            return False
        self._commit(run, t, decision, replacing, task)
        self.straight[replacing if replacing is not None else len(tasks) - 1] = dict(cycle.phases)
        record = decision.record() | ({"via_tf": self._vias} if self._vias else {})
        chosen = next(tr for tr in tracks if tr.id == decision.track)
        record |= logged(self.cycles.found(chosen, windows[chosen.id], start, yaw), cycle)  # (cached)
        self.decisions.append(record | {"task": replacing if replacing is not None else len(tasks) - 1,
                                        "tf": {p: round(v, 3) for p, v in cycle.phases.items()}})
        self.planning_s.append(time.perf_counter() - clock)
        return True

    def _part_of(self, context, track: int, tracks: list) -> int:
        """The pool part a decided track is: the sensor's identity; with the camera the truth names
        it (``truth.part_under``: the metrics' name of the task) and the task aims at the track
        (``view.aim``)."""
        if not self.view.camera:
            return track
        part = self.truth.part_under(context, next(tr for tr in tracks if tr.id == track).position)
        self.view.aim(part, track)
        return part

    def _cycle(self, decision, tracks, windows, t: float, start, yaw: float, free: dict, keep: list):
        """The chosen grasp's cycle from the min-tf model (``LineCycles.phases``; the tray's parts
        those of tasks ``keep``, ``grip.in_tray``), to the free slot its kind's ``fill`` takes
        (``slot_choice``: ``decision.slot`` set); None where no tf fits a phase (logged)."""
        track = next(tr for tr in tracks if tr.id == decision.track)
        kind = self.line.kind(track.kind)
        filled = in_tray(self.scenario.pick, keep)
        def cycle_of(slot):
            return self.cycles.phases(track, windows[track.id], decision.grasp, t, start, yaw, slot, filled)
        try:
            if kind.fill == "cycle" and isinstance(decision.slot, int):
                near = nearest(self.scenario.pick, kind_part(self.scenario.pick, kind.name), free[kind.name],
                               decision.point)
                decision.slot, cycle = choose(cycle_of, near)
            else:
                cycle = cycle_of(decision.slot)
            if isinstance(decision.slot, OutPlace):  # (outbelt46: the point on the outgoing belt chosen)
                decision.slot = self.cycles.out_place
            return cycle
        except NoTfFits as error:
            self.decisions.append(decision.record() | {"not started": f"no tf fits: {error}"})
            self.cycles.drop_grip(track, windows[track.id], start, yaw)  # the next look: the next grip
            self.cycles.drop_early(track.id)  # and the approach after the entry
            return None

    def _arm_q(self, context) -> np.ndarray:
        """The arm's present joint positions (the station's state output)."""
        station = self.built.station
        q = station.diagram.GetOutputPort("state").Eval(station.diagram.GetMyContextFromRoot(context))
        return q[:self.built.arm.num_positions()]

    def _tool_now(self, q) -> tuple:
        """(point, yaw) of the tool at the arm's posture ``q``."""
        arm = self.built.arm
        context = arm.CreateDefaultContext()
        arm.SetPositions(context, q)
        X = arm.GetFrameByName(self.scenario.robot.end_effector).CalcPoseInWorld(context)
        return X.translation(), float(tool_yaw(X.rotation().matrix()))

    def _fit(self, run, t: float, decision, replacing, cycle, tracks, part: int):
        """The decision's task (``LineCycles.task_of``: its approach from the model's start, or —
        a replaced task whose approach is under way — from now), each phase the plan splits by a
        via stretched to what the via's legs need (``LineCycles.detours``, on the plan the run
        will follow: ``DETOUR_PASSES`` at most, the part's way moving with the approach); None,
        logged, where the grasp then leaves reach (the track's lead grows by it: ``extra``)."""
        tasks = self.scenario.pick.tasks
        name = self.built.station.config.parts[part].name
        track = next(tr for tr in tracks if tr.id == decision.track)
        k = len(tasks) if replacing is None else replacing
        tf = cycle.phases
        begin = max(t, decision.grasp - tf["approach"] - tf["descend"] - self.cycles.extra.get(track.id, 0.0))
        if replacing is not None and t >= tasks[replacing].start - 1e-9:
            begin = t  # its approach under way: restarted from the present state
        task = self.cycles.task_of(name, decision.slot, decision.grasp, t, cycle, begin)
        if task.bin:  # the grid's next spot over its bin's floor, by the tasks before it there
            box = next(b for b in self.scenario.pick.bins if b.name == task.bin)
            spots = bin_spots(box, next(p for p in self.scenario.pick.parts if p.name == name))
            task = replace(task, bin_at=list(spots[sum(o.bin == task.bin for o in tasks[:k]) % len(spots)]))
        mass = held_mass(self.scenario, self.line.kind(track.kind).mass)
        self._vias = {}  # phase → the min tfs of its via's two legs (the decision log's ``via_tf``)
        why = f"the plan's vias still ask for more after {DETOUR_PASSES} passes"
        for _ in range(DETOUR_PASSES):
            scenario = self.planning()
            trial = [*tasks[:k], task, *tasks[k + 1:]]
            scenario = replace(scenario, pick=replace(scenario.pick, tasks=trial))
            replans = (*run.replans[:k], Replan(), *unpinned(run.replans[k + (replacing is not None):], k))
            try:
                needs = self.cycles.detours(scenario, line_plan(scenario, replans, self.built.arm), k, mass)
            except NoTfFits as error:
                why = f"no tf fits a via's leg: {error}"  # (its grip kept: ``grip``)
                break
            short = fitted(task, needs, cycle.phases)
            self._vias = {p: [round(v, 3) for v in legs[:2]] for p, legs in needs.items()}
            if not short:
                return task
            task = replace(task, **short)
            grasp = task.start + task.approach.tf + task.descend.tf
            if "approach" in short:
                self.cycles.extra[track.id] = self.cycles.extra.get(track.id, 0.0) + grasp - decision.grasp
            hit = blocker(replace(track, axis=grip_axis(cycle.yaws[0])), tracks, grasp, t, self.timing)
            if grasp > decision.deadline + 1e-9 or hit is not None:
                why = (f"the approach's via needs {task.approach.tf:.3f} s: grasp at {grasp:.2f} s "
                       + (f"blocked (track {hit})" if hit is not None else
                          f"after the deadline {decision.deadline:.2f} s"))
                break
            decision.grasp, decision.point = grasp, tuple(float(c) for c in track.at(grasp, t))
        self.decisions.append(decision.record() | {"not started": why})
        return None

    def _commit(self, run, t: float, decision, replacing, task) -> None:
        """The decision's ``task`` (``_fit``) into the run's tasks (and its per-task records)."""
        tasks = self.scenario.pick.tasks
        if replacing is None:
            tasks.append(task)
            run.replans.insert(len(tasks) - 1, Replan())  # before the holds (``plan.line_plan``)
            run.checks.append([])
            run.refused.append(None)
            k = len(tasks) - 1
        else:
            tasks[replacing], k = task, replacing
            run.replans[k], run.checks[k], run.refused[k] = Replan(), [], None
            run.replans[:] = unpinned(run.replans, k)  # (its approach restarts: ``watch``)
        part = [p.name for p in self.built.station.config.parts].index(task.part)
        task.close_delay = close_delay(self.line.truth, part)  # the truth's jitter (robust)
        self.committed[k] = [decision.track, decision.grasp, decision.point]

