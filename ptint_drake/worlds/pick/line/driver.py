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
- **while a task approaches** (before its descend), the grasp point predicted now is compared with
  the committed one; beyond ``line.redecide_mm`` (a belt without an encoder running faster or
  slower than declared: its speed is then learned from the track, ``view.LineView.learned``) the
  window is checked at the committed time with that speed: still
  in it, the task goes on (the targets follow the track: ``kept``); out of it, the scheduler
  decides again from now and the task is replaced (``replaced``: its approach restarts from the
  present state, its tf stretched to the new grasp time; nothing feasible: the task goes on).

Every decision goes to the log (``decisions``: metrics.json ``line.decisions``); looks that find
nothing new are not repeated in it.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ptint_drake.config.pick import MoveConfig, PickTaskConfig
from ptint_drake.worlds.pick.grasp_gate import finger_extent
from ptint_drake.worlds.pick.line.arrivals import close_delay, line_scenario
from ptint_drake.worlds.pick.line.metrics import line_metrics
from ptint_drake.worlds.pick.line.plan import IDLE_TF
from ptint_drake.worlds.pick.line.scheduler import Timing, decide, drifted
from ptint_drake.worlds.pick.line.truth import LineTruth
from ptint_drake.worlds.pick.line.view import LineView
from ptint_drake.worlds.pick.scene import belt_frame
from ptint_drake.worlds.pick.tasks import Replan

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


class NoLine:
    """The pick run of a task list: no line (``PickRun`` calls the same hooks; they do nothing)."""

    active = False

    def __init__(self, scenario):
        self.scenario = scenario

    def bind(self, built) -> None:
        pass

    def start(self, context) -> None:
        pass

    def restore(self, context) -> None:
        pass

    def stops(self, duration: float) -> list[float]:
        return []

    def at_stop(self, run, context, t: float) -> bool:
        return False

    def add_metrics(self, metrics: dict, series: dict) -> None:
        pass

    def planning(self):
        return None


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

    def bind(self, built) -> None:
        """The (re)built diagram's handles."""
        if self.truth is None:
            self.truth = LineTruth(built.station, self.releases, self.line.speed_steps)
            task = PickTaskConfig()
            self.timing = Timing(lead=task.approach.tf + task.descend.tf, margin=task.margin,
                                 finger=finger_extent(built.station))
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
            kind = next(c for c in self.line.catalog if c.name == tr.kind)  # (a camera's: as classified)
            self._beliefs[tr.id] = (tr.s - tr.speed * t, lateral, yaw, kind.shape, list(kind.size))
            self._speeds[tr.belt] = tr.speed

    def add_metrics(self, metrics: dict, series: dict) -> None:
        """metrics.json ``line`` (``metrics.line_metrics``)."""
        metrics["line"] = line_metrics(self.scenario, self, metrics, series)

    def stops(self, duration: float) -> list[float]:
        """The truth's stops and the scheduler's looks (every ``decide_period``)."""
        looks = np.arange(IDLE_TF, duration, self.line.decide_period).round(9)
        return sorted(set(self.truth.stops(duration)) | set(looks.tolist()))

    def at_stop(self, run, context, t: float) -> bool:
        """The truth's acts, then a decision if one is due; True when the tasks changed."""
        self.truth.at_stop(context, t)
        if t < IDLE_TF - 1e-9:
            return False
        tasks = self.scenario.pick.tasks
        if tasks and t < run.built.plan.end - 1e-9:
            return self._watch(run, context, t)
        return self._choose(run, context, t)

    def _watch(self, run, context, t: float) -> bool:
        """The last task's grasp point against the committed one, before its descend."""
        k = len(self.scenario.pick.tasks) - 1
        plan = run.built.plan
        if t >= plan.schedule.segments[plan.segment_index(k, "descend", 0)].start - 1e-9:
            return False
        track_id, grasp, point = self.committed[k]
        track = next((tr for tr in self.view.tracks(context, t) if tr.id == track_id), None)
        if track is None:
            return False
        drift = drifted(track, grasp, point, t, 1e-3 * self.line.redecide_mm)
        if not drift:
            return False
        if np.isfinite(track.measured) and not self._has_encoder(track.belt):
            self.view.learned[track.belt] = track.measured  # the belt's speed, as its track shows it
            track = replace(track, speed=track.measured)
        s_in, s_out = self.view.window(track)
        s = track.s + track.speed * (grasp - t)
        entry = {"t": round(t, 4), "task": k, "track": track_id, "drift_mm": round(1e3 * drift, 2),
                 "speed": round(track.speed, 4)}
        if s_in <= s <= s_out - track.speed * self.timing.slack:
            self.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
            self.decisions.append(entry | {"redecide": "kept"})
            return False
        if self._choose(run, context, t, replacing=k):
            self.replaced.append({"t": t, "task": k, "drift_mm": 1e3 * drift})
            self.decisions[-1]["redecide"] = "replaced"
            return True
        self.decisions.append(entry | {"redecide": "nothing feasible: kept"})
        self.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
        return False

    def _has_encoder(self, belt: str) -> bool:
        return any(b.name == belt and b.encoder for b in self.line.belts)

    def _choose(self, run, context, t: float, replacing=None) -> bool:
        """A decision from now; a task appended (or task ``replacing`` replaced): True."""
        tasks = self.scenario.pick.tasks
        if t + cycle_time(PickTaskConfig()) > self.scenario.duration:
            return False  # no cycle fits before the end
        tracks = self.view.tracks(context, t)
        windows = {tr.id: self.view.window(tr) for tr in tracks}
        keep = [k for k in range(len(tasks)) if k != replacing]
        assigned = {self.committed[k][0] for k in keep}
        used = {tasks[k].slot for k in keep}
        free = {c.name: [c.bin] if c.bin else [j for j in c.slots if j not in used]
                for c in self.line.catalog}
        decision = decide(t, tracks, windows, assigned, free, self.timing)
        if decision.track is not None:
            station = self.built.station
            q = station.diagram.GetOutputPort("state").Eval(station.diagram.GetMyContextFromRoot(context))
            if self.view.reachable(np.asarray(decision.point), q[:self.built.arm.num_positions()]) is None:
                decision.skipped.append((decision.track, "out of reach by IK at the grasp"))
                decision.track = decision.grasp = decision.slot = decision.point = None
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
        self._commit(run, t, decision, replacing, part)
        self.decisions.append(record | {"task": replacing if replacing is not None else len(tasks) - 1})
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

    def _commit(self, run, t: float, decision, replacing, part: int) -> None:
        """The decision's task into the run's tasks (and its per-task records)."""
        tasks, default = self.scenario.pick.tasks, PickTaskConfig()
        name = self.built.station.config.parts[part].name
        if replacing is None:
            start = max(t, decision.grasp - self.timing.lead)
            task = PickTaskConfig(part=name, start=start, **_destination(decision.slot))
            tasks.append(task)
            run.replans.append(Replan())
            run.checks.append([])
            run.refused.append(None)
            k = len(tasks) - 1
        else:
            tf = decision.grasp - default.descend.tf - t
            task = PickTaskConfig(part=name, start=t, **_destination(decision.slot),
                                  approach=MoveConfig(tf, default.approach.beta))
            tasks[replacing], k = task, replacing
            run.replans[k], run.checks[k], run.refused[k] = Replan(), [], None
        task.close_delay = close_delay(self.line.truth, decision.track)  # the truth's jitter (robust)
        self.committed[k] = [decision.track, decision.grasp, decision.point]


def _destination(where) -> dict:
    """A decision's destination as a task's fields: a tray slot (an index) or a bin (its name)."""
    return {"bin": where} if isinstance(where, str) else {"slot": where}
