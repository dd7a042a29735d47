"""The line's phase times from the minimum phase time model (``phase_time.PhaseTimes``, issue 44).

The scheduler asks, per track, how long the arm needs from where it stands to a grasp of that
part (``LineCycles.lead``: the approach's min tf from the tool's present point and yaw to
``clearance`` above the part riding its belt, plus the descend's — at least the fingers' close):
a grasp time at least that far ahead is one the arm makes within its joint speed and torque
limits (× ``phase_time.MARGIN``).  A lead counts from now, or from the part's entry into its
reach window when it is still upstream; there the approach starts before the entry, so that it
ends as the part enters (the approach's min tf found again for the part where it is at that
earlier start: a fixed point, ``EARLY_PASSES``; the grasp then one descend after the entry).
Every sample of both ways has a top-down posture by Drake's IK (``phase_time``), and the part is
in reach over the whole descend, the grasp and the lift: the scheduler's old rule — the part in
reach from the approach's start on, the approach from the tray to the window's entry passing the
waist axis in 1.5–2.5 s after the part entered (line_short seed 0: 2.45 s) — is kept for the
approach's end only.  Where a way has no top-down posture all along, the approach starts up to
``WAITS`` later (the lead counts the wait).  A lead is cached per track and ``LEAD_STEP`` of its
belt coordinate (a free arm looks every ``decide_period``; the tool holds still meanwhile).

The chosen task's tfs (``LineCycles.phases``) are one ``phase_time.cycle_time`` from the tool's
point and yaw, the part at the approach's start riding its belt (approach, descend), the payload
held (lift, carry, place), to its slot and back up (retreat); a part put on an outgoing belt:
``phase_time.cycle_time`` with its place riding that belt (carry, place and retreat) to the point
``out_belt.choose`` picks (a task being replaced keeps its old point among the placed ones:
conservative).  The grip and place yaws are chosen by the part's symmetry (``grip``), and the
task carries them (``grip_yaw``, ``place_yaw``) to the plan and the targets.

``detours`` — what the plan makes of a task: a phase the plan splits by a via (``route``: around
the waist axis; ``obstacles``: above a part in the way) shares the phase's tf between its two legs
by their lengths, and the via's leg turns the tool's whole yaw; the min-tf model above takes the
straight way.  Measured (line_surplus seed 2 at 22.19 s): a 0.264 s approach got a via 45 mm above
the slot, its leg 0.1 s with a 90° turn, and the wrist ran at 9 rad/s, 766 N·m commanded, into the
conveyor.  So the task's plan is made (``plan.line_plan``, what the run will follow) and each via's
two legs are asked of the model on their own — from the previous segment's target, as the plan's
way starts — and the phase is split to give each leg its own (``via_split``: the driver stretches
the task, or gives it up where its grasp then leaves reach).

The start state: the model starts each phase at rest on its way, from the tool's present point
(the arm's posture read at the decision).  Measured over 110 segment starts of two runs
(line_surplus seed 2 and the slowed-belt case of tests/e2e, with the fixes here) the largest
joint speed at a segment's start was 0.31 of its limit (a lift, leaving the belt's speed; median
0.02): no margin is added for it.  The two runaways blamed on chaining were a via (above) and a
drift kept with its part out of reach at the approach's end (``driver``), not a carried velocity.

``estimate`` — the line's capacity by the model: per kind of the catalog, one cycle from
``clearance`` above its first slot to a part at the middle of its reach window on its belt (no
lateral offset, yaw 0) and back to that slot, the tool on the slot's yaw branch (modulo π) nearest
its yaw at the initial posture (the iiwa's is π: at 0 IK found no posture); 60 / the mean cycle,
picks per minute (the arrival warning's number, the surplus line's, ``scripts/line_capacity.py``).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Optional

import numpy as np

from ptint_drake.config.pick import MoveConfig, PartConfig, PickTaskConfig
from ptint_drake.config.part_shape import part_height
from ptint_drake.worlds.pick.cell import place_point
from ptint_drake.worlds.pick.phase_time import Cycle, NoTfFits, PhaseTimes, cycle_time, held_mass
from ptint_drake.worlds.pick.line.grip import Grips, grip_axis, puts, slot_yaw
from ptint_drake.worlds.pick.route import nearest_branch, tool_yaws
from ptint_drake.worlds.pick.scene import belt_frame
from ptint_drake.worlds.pick.out_belt import OutPlace, across_yaw, choose, place_of, placed_on, ride_of
from ptint_drake.worlds.pick.tasks import place_target
from ptint_drake.worlds.pick.ways import nominal, segment_target, start_error

LEAD_STEP = 0.01  # m along the belt: a lead's cache key
WAITS = (0.0, 0.25, 0.5, 1.0, 1.5, 2.0)  # s: an approach's start put off, when its way leaves the reach
EARLY_PASSES = 3  # fixed-point passes of an approach that ends as its part enters reach
PHASE_NAMES = ("approach", "descend", "lift", "carry", "place", "retreat")


class LineCycles:
    """The min-tf model of a line's station and the leads it gave (module docstring)."""

    def __init__(self, scenario, model: Optional[PhaseTimes] = None, window_at=None,
                 finger: tuple = (0.006, 0.02)):
        self.scenario = scenario
        self.model = model or PhaseTimes.of(scenario)
        self.window_at = window_at  # (belt, lateral, height) → reach window (``LineView.window_at``)
        self.finger = finger  # m, the open fingers' (thickness, width) (``grasp_gate.finger_extent``)
        self.out_place: Optional[OutPlace] = None  # the last ``phases``' point on an outgoing belt
        self.task = PickTaskConfig()
        self._leads: dict = {}
        self.extra: dict = {}  # track → s its approach's via needs beyond the straight way (``detours``)
        self.plain: set = set()  # tracks whose approach starts after the entry (``drop_early``)
        self.choice = Grips()  # the grip yaws of the tracks (``grip``)

    def lead(self, track, window: tuple, now: float, start, yaw: float):
        """s from now, or from the part's entry into its ``window`` if later, to the earliest grasp
        of ``track`` (module docstring), the tool at ``start`` turned to ``yaw``; a str naming why
        no tf fits."""
        found = self.found(track, window, start, yaw)
        if isinstance(found, str):
            return found
        return float(_lead_of(found)) + self.extra.get(track.id, 0.0)

    def found(self, track, window: tuple, start, yaw: float):
        """(approach, descend, wait, early, grip) of ``_lead``, cached, or a str."""
        ahead, key = _key(track, window, start, yaw)
        if key not in self._leads:
            self._leads[key] = self._lead(track, ahead, start, yaw)
        return self._leads[key]

    def _lead(self, track, ahead: float, start, yaw: float):
        """(approach, descend, wait, early, grip) or a str naming why no tf fits (module docstring):
        the approach starting at the entry (or now) + wait, the first of ``WAITS`` at which one of
        the track's grip yaws (``grip.grips``, in their order) has a top-down posture all along its
        ways; then, for a part upstream, one that starts ``early`` s before and ends at the entry +
        a wait (the first of ``WAITS`` that fits, ``_early``), where its lead is the shorter."""
        ride = track.speed * np.asarray(track.direction)
        up = np.array([0.0, 0.0, self.task.clearance])
        grip = 0.0

        def approach_from(t: float, guess: Optional[float] = None) -> float:
            """The approach's min tf, the part where it is at t (the fixed point from ``guess``: a
            riding way too short to reach the window has no top-down posture all along)."""
            self.model.last = guess or self.model.last
            return self.model.min_tf(start, np.asarray(track.at(t, 0.0)) + up, ride, 0.0,
                                     self.task.approach.beta, (yaw, grip))

        def descend_at(t: float) -> float:  # the descend's, the part where it is at t
            at = np.asarray(track.at(t, 0.0))
            return max(self.model.min_tf(at + up, at, ride, 0.0, self.task.descend.beta, (grip, grip)),
                       self.task.margin / self.model.gripper_speed)

        best, why = None, ""
        for wait, grip in ((w, g) for w in WAITS for g in self.grips(track, yaw)):
            try:
                approach = approach_from(ahead + wait)
                best = (approach, descend_at(ahead + wait + approach), wait, 0.0, grip)
                break
            except NoTfFits as error:
                why = why or f"no tf fits: {error}"  # the way from now (wait 0): where the part is
        if best is None:
            return why
        for wait in WAITS if ahead > 0.0 and track.id not in self.plain else ():
            if wait + best[1] >= _lead_of(best):
                break  # no shorter lead left
            found = self._early(approach_from, ahead, wait)
            try:
                if found is not None:
                    early = (found[0], descend_at(ahead + wait - found[1] + found[0]), wait, found[1], grip)
                    return early if _lead_of(early) < _lead_of(best) else best
            except NoTfFits:
                continue
        return best

    def drop_grip(self, track, window: tuple, start, yaw: float) -> None:
        """The track's leads from now on without the grip yaw its lead chose (``found``: its cycle
        found no tf, ``driver``); the next candidate is tried at the next look (``grips``)."""
        self.choice.drop(track.id, self.found(track, window, start, yaw))
        self._leads = {k: v for k, v in self._leads.items() if k[0] != track.id}

    def drop_early(self, track_id: int) -> None:
        """The track's leads from now on without an early approach (its cycle found none: ``driver``)."""
        self.plain.add(track_id)
        self._leads = {k: v for k, v in self._leads.items() if k[0] != track_id}

    @staticmethod
    def _early(approach_from, ahead: float, wait: float):
        """(approach, early): an approach's min tf that ends with the part in its window, and how
        long before the entry + ``wait`` it starts (not before now) — a fixed point,
        ``EARLY_PASSES`` at most; None where none ends so or a way has no top-down posture."""
        trial = ahead + wait
        for _ in range(EARLY_PASSES):
            try:
                tf = approach_from(ahead + wait - trial, trial)
            except NoTfFits:
                return None
            if tf + wait >= trial - 1e-9:  # it ends with the part in its window
                return tf, trial
            trial = tf  # it would end before the part enters: start it later
        return None

    def fits(self, track, begin: float, grasp: float, now: float, start, yaw: float,
             grip: Optional[float] = None) -> bool:
        """Whether an approach from the tool at ``start`` (turned to ``yaw``) starting at ``begin``
        and the descend make the grasp of ``track`` at ``grasp``: their min tfs, the part where it
        is at ``begin`` (a kept task, ``driver``: ``grip``, its chosen grip yaw — default the
        track's first, ``grips``); False where no tf fits."""
        ride = track.speed * np.asarray(track.direction)
        up = np.array([0.0, 0.0, self.task.clearance])
        grip = self.grips(track, yaw)[0] if grip is None else nearest_branch(yaw, grip)
        try:
            part = np.asarray(track.at(begin, now))
            approach = self.model.min_tf(start, part + up, ride, 0.0, self.task.approach.beta, (yaw, grip))
            at = part + ride * approach
            descend = max(self.model.min_tf(at + up, at, ride, 0.0, self.task.descend.beta, (grip, grip)),
                          self.task.margin / self.model.gripper_speed)
        except NoTfFits:
            return False
        return begin + approach + descend + self.extra.get(track.id, 0.0) <= grasp + 1e-9

    def axis(self, track, window: tuple, start, yaw: float) -> tuple:
        """The fingers' closing axis (world) at the grip yaw the lead chose (``found``)."""
        found = self.found(track, window, start, yaw)
        return track.axis if isinstance(found, str) else grip_axis(found[4])

    def grips(self, track, yaw: float) -> list:
        """rad: the grip yaws of ``track`` for the tool at ``yaw``, preferred first (``grip.Grips``)."""
        pick = self.scenario.pick
        return self.choice.of(track.id, kind_part(pick, track.kind), track_yaw(track), yaw,
                              slot_yaw(pick, track.kind))

    def phases(self, track, window: tuple, grasp: float, now: float, start, yaw: float, slot,
               filled: tuple = ()) -> Cycle:
        """The cycle of a grasp of ``track`` (reach ``window``) at ``grasp`` (module docstring), its
        approach starting its min tf and the descend's before it (or now), at the lead's grip yaw and
        the first place yaw that fits (``grip.puts``, ``filled``: the tray's parts): ``Cycle.yaws``."""
        pick = self.scenario.pick
        kind = kind_part(pick, track.kind)
        found = self.found(track, window, start, yaw)
        begin, grip = now, self.grips(track, yaw)[0]
        if not isinstance(found, str):
            begin = max(now, grasp - found[0] - found[1] - self.extra.get(track.id, 0.0))
            self.model.last, grip = found[0], found[4]  # (the riding approach's fixed point: ``_early``)
        if isinstance(slot, OutPlace):
            return self._riding(track, grasp, now, begin, start, yaw, slot, kind, grip)
        task = replace(self.task, **destination(slot))
        place = destination_place(pick, slot, kind)
        options = [grip] if isinstance(slot, str) else puts(  # a bin: the tool keeps its grasp's yaw
            kind, place, _place_yaw(pick, task, grip), grip, list(filled), self.finger, task.margin)
        error = NoTfFits(f"no place yaw at slot {slot} keeps the open fingers clear of the tray's parts")
        for put in options:
            try:
                return cycle_time(self.model, track.at(begin, now), track.speed * np.asarray(track.direction),
                                  place, put, track_yaw(track), held_mass(self.scenario, kind.mass), task,
                                  start, yaw, grip=grip, put=put)
            except NoTfFits as e:
                error = e
        raise error

    def _riding(self, track, grasp: float, now: float, begin: float, start, yaw: float, slot, kind,
                grip: float) -> Cycle:
        """``phases`` of a part put on an outgoing belt (``out_belt.choose``: the point, then the
        cycle to it riding the belt); the point chosen: ``out_place``."""
        pick = self.scenario.pick
        belt = next(b for b in pick.belts if b.name == slot.belt)
        window = self.window_at(slot.belt, 0.0, part_height(kind.shape, kind.size) / 2)
        put = across_yaw(belt, grip)
        mass = held_mass(self.scenario, kind.mass)
        ride = track.speed * np.asarray(track.direction)

        def cycle_of(along: float) -> Cycle:
            place0 = place_of(pick, slot.belt, kind, along)
            return cycle_time(self.model, track.at(begin, now), ride, place0, put, track_yaw(track), mass,
                              self.task, start, yaw, place_ride=ride_of(belt), begin=begin, grip=grip)

        placed = placed_on(pick.tasks, slot.belt, {p.name: p for p in pick.parts})
        self.out_place, cycle = choose(pick, slot.belt, window, grasp, cycle_of, kind, placed, self.finger[1],
                                       track.at(grasp, now))
        return cycle

    def task_of(self, part: str, slot, grasp: float, now: float, cycle: Cycle,
                begin: Optional[float] = None) -> PickTaskConfig:
        """The ``PickTaskConfig`` of ``cycle`` for a grasp at ``grasp``: its approach starting at
        ``begin`` (default: its min tf before the descend, or now) and stretched so that the
        descend ends at the grasp."""
        tf = cycle.phases
        if begin is None:
            begin = max(now, grasp - tf["approach"] - tf["descend"])
        moves = {p: MoveConfig(tf[p], getattr(self.task, p).beta) for p in PHASE_NAMES}
        moves["approach"] = MoveConfig(grasp - tf["descend"] - begin, self.task.approach.beta)
        yaws = {"grip_yaw": cycle.yaws[0], "place_yaw": cycle.yaws[1] if isinstance(slot, int) else None}
        return replace(self.task, part=part, start=begin, **destination(slot), **moves, **yaws)

    def detours(self, scenario, plan, k: int, mass: float) -> dict:
        """phase → (tf₁, tf₂, share): the min tfs (s) of the via's leg and of the rest of task
        ``k``'s phase split by a via in ``plan`` (the plan of ``scenario``; module docstring), and
        the share of the phase's tf the plan gives the via's leg; ``mass`` (kg) held on a carry;
        only phases with a via.  ``NoTfFits`` where a leg has none."""
        world = nominal(scenario, self.model.arm)
        yaws = tool_yaws(world, plan)
        segments, times = plan.segments, plan.schedule.segments
        needs = {}
        for i, seg in enumerate(segments[:-1]):
            if seg.task != k or seg.phase != "via":
                continue
            nxt, s0, s1 = segments[i + 1], times[i], times[i + 1]
            payload = mass if nxt.phase == "carry" else 0.0
            via = segment_target(world, plan, i, s0.start)[0]
            ride = world.parts[nxt.index][1] if nxt.kind == "part" else None
            first = self.model.min_tf(via + start_error(world, plan, i), via, None, payload, s0.beta, yaws[i])
            second = self.model.min_tf(via, segment_target(world, plan, i + 1, s1.start)[0], ride, payload,
                                       s1.beta, yaws[i + 1])
            needs[nxt.phase] = (first, second, s0.tf / (s0.tf + s1.tf))
        return needs


def estimate(scenario, view, model: Optional[PhaseTimes] = None) -> tuple:
    """(picks per minute, mean cycle s) of the line by the model (module docstring); ``view``
    gives the reach windows (``LineView.window_at``).  Asked of a fresh ``model`` (no posture
    solved yet: a run's warning before it starts) it is kept for the process by what it reads
    (``_ESTIMATES``), with what it leaves in the model — the postures it solved and the riding
    phases' last tf, which the run's own phases start from — so a hit leaves the model as the
    computation would: a sample's run does not depend on what its worker ran before."""
    pick = scenario.pick
    fresh = model is not None and not model.postures
    key = repr((scenario.robot, scenario.controller,  # (its K, rot_scale and pinv_damping)
                pick.gripper, pick.belts, pick.tray, pick.bins, pick.line.catalog, pick.line.arrivals,
                None if model is None else (model.torque_share, model.speed_share, model.samples,
                                            model.last)))
    if fresh and key in _ESTIMATES:
        found, postures, last = _ESTIMATES[key]
        model.postures.update(postures)
        model.last = last
        return found
    model = model or PhaseTimes.of(scenario)
    found = _estimate(scenario, view, model)
    if fresh:
        _ESTIMATES[key] = (found, dict(model.postures), model.last)
    return found


# What ``estimate`` reads of a fresh model's cell (the controller side's, never the truth) → its
# result and what it left in the model: a study's samples (each a run in the same worker) differ
# in the truth only — measured, line_assembly at load 12: 0.32 CPU s saved a sample, of ~13–17 s.
_ESTIMATES: dict = {}


def _estimate(scenario, view, model: PhaseTimes) -> tuple:
    """``estimate``, computed."""
    pick, task = scenario.pick, PickTaskConfig()
    belts = {b.name: b for b in pick.belts}
    totals = []
    for kind in pick.line.catalog:
        part = kind_part(pick, kind.name)
        for arrival in pick.line.arrivals:
            if arrival.mix and not arrival.mix.get(kind.name):
                continue
            belt = belts[arrival.belt]
            height = part_height(part.shape, part.size)
            s_in, s_out = view(arrival.belt, 0.0, height / 2)
            x = belt_frame(belt).multiply(np.array([0.5 * (s_in + s_out), 0.0, height / 2]))
            ride = belt.speed * np.asarray(belt.direction) / np.linalg.norm(belt.direction)
            if kind.belt:  # the point of its reach window's middle, at t = 0 (``out_belt``)
                out = belts[kind.belt]
                w = view(kind.belt, 0.0, height / 2)
                place0 = place_of(pick, kind.belt, part, 0.5 * (w[0] + w[1]))
                put = across_yaw(out, 0.0)
                totals.append(cycle_time(model, x, ride, place0, put, 0.0, held_mass(scenario, kind.mass),
                                         task, place0 + [0.0, 0.0, task.clearance], put,
                                         place_ride=ride_of(out)).total)
                continue
            where = kind.bin or kind.slots[0]
            place = destination_place(pick, where, part)
            place_yaw = _place_yaw(pick, replace(task, **destination(where)), 0.0)
            place_yaw = nearest_branch(model.initial_yaw(), place_yaw)
            cycle = cycle_time(model, x, ride, place, place_yaw, 0.0, held_mass(scenario, kind.mass), task)
            totals.append(cycle.total)
    mean = float(np.mean(totals))
    return 60.0 / mean, mean


def destination(where) -> dict:
    """A decision's destination as a task's fields: a tray slot (an index), a bin (its name) or a
    point on an outgoing belt (``out_belt.OutPlace``)."""
    if isinstance(where, OutPlace):
        return where.fields()
    return {"bin": where, "slot": None} if isinstance(where, str) else {"slot": where, "bin": ""}


def _place_yaw(pick, task, grasp_yaw: float) -> float:
    """rad: the tool's yaw at a task's place — its slot's on the tray, or over a bin the yaw it
    grasped at (``tasks.place_target``: the tool keeps it; a line's part is declared nowhere)."""
    return grasp_yaw if task.bin else place_target(pick, task)[2]


def destination_place(pick, where, part) -> np.ndarray:
    """The place point of ``part`` at a tray slot (an index) or over a bin (its name)."""
    if isinstance(where, str):
        return place_point(pick, "bin", [b.name for b in pick.bins].index(where), part)
    return place_point(pick, "slot", where, part)


def _lead_of(found: tuple) -> float:
    """s from the entry (or now) to the grasp of a ``_lead`` (approach, descend, wait, early, grip)."""
    return found[0] + found[1] + found[2] - found[3]  # approach + descend + wait − early


def _key(track, window: tuple, start, yaw: float) -> tuple:
    """(s until the part enters ``window``, ≥ 0; a lead's cache key)."""
    ahead = max(0.0, (window[0] - track.s) / track.speed) if track.speed > 1e-9 else 0.0
    return ahead, (track.id, round((track.s + track.speed * ahead) / LEAD_STEP),
                   tuple(np.round(np.asarray(start), 3)), round(yaw, 2))


def track_yaw(track) -> float:
    """rad: the yaw of a track's closing axis (world)."""
    return float(math.atan2(track.axis[1], track.axis[0]))


def kind_part(pick, kind: str) -> PartConfig:
    """A ``PartConfig`` of the catalog kind ``kind`` (its shape, size, mass and friction)."""
    k = pick.line.kind(kind)
    return PartConfig(name=k.name, shape=k.shape, size=list(k.size), mass=k.mass, friction=k.friction)
