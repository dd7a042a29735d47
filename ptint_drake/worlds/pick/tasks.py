"""A pick and place as prescribed-time segments: the scenario's ``pick`` block and its plan.

A scenario with a ``pick`` block (``PickConfig``: the world of ``pick.config`` — gripper, belts,
parts, tray — and the ``tasks``) has no ``interceptions`` of its own: each task (``PickTaskConfig``:
one part to one tray slot) becomes six segments of the interceptor's schedule, one after the
other, each a prescribed-time interception (SPEC 2.1) of its own target:

1. ``approach`` — the pre-grasp pose ``clearance`` above the part's *simulated* centre as it
   rides its belt (a moving target), grasped from above (task ``top_down``: the tool's approach
   axis down, the fingers across the part's x axis);
2. ``descend`` — the part's centre itself (moving).  The fingers are commanded to close
   ``(opening − width) / (2 · speed)`` before this segment's tf, so that they reach the part at
   its prescribed time; the arm holds on the moving part for ``dwell`` while the grip builds up;
3. ``lift`` — ``lift_height`` straight above where the part was when the lift started (latched
   at the segment's start: a target that moved with the hand would never be reached);
4. ``carry`` — ``lift_height`` above the slot, turned to the slot's yaw (an unknown payload in
   the hand: the model-free controller is not told);
5. ``place`` — the slot pose (the part's centre ``height / 2`` above the tray's top); the fingers
   open at this segment's tf + ``dwell``;
6. ``retreat`` — ``clearance`` above the slot, starting ``dwell`` after the fingers opened.

A task with a ``bin`` instead of a ``slot`` (``pick.bins``: an open box) carries the part to
``lift_height`` above the bin's drop point (``scene.bin_drop``: over its centre, or ``bin_at`` from
it, the part's bottom ``scene.BIN_DROP_CLEARANCE`` above its walls), lowers it there, opens the
fingers and retreats up; the tool keeps the yaw it grasped at (``place_target``).  A task with a ``belt`` (an
outgoing belt of ``pick.belts``) puts the part on that belt at ``belt_at`` (its coordinate along
the belt at t = 0): the carry, the place and the retreat aim at that point as it rides the belt at
the belt's speed as the plan knows it (``PlanSegment.ride``), the part's closing axis across the
belt (``place_target``); ``out_belt`` chooses the point.

A *via* (``Via``, decided by ``worlds.pick.route``) splits a task's first approach or its carry in
two — a segment of its own (phase ``via``) to a fixed point, then the approach or carry, together
in the segment's tf: the way around the arm's base when the straight way passes its waist axis.
The tool grips a part at its centre, or ``config.grip_height`` above it where the fingertips would
come too near its belt (or the tray at the place); every target over the part or its place rises
by as much.  Times: the approach starts at the task's ``start`` (0: right after the previous
task's retreat); each later segment at the previous one's prescribed time, the lift and the
retreat ``dwell`` later.  ``pick_plan`` turns the block into the schedule, one ``PlanSegment`` per
segment (what ``pick.targets.PickTargets`` aims at) and the gripper's commands.
"""

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.pick import PHASES, MoveConfig, PickConfig, PickTaskConfig  # noqa: F401
from ptint_drake.systems.perception.part_fit import yaw_symmetry
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.worlds.pick.config import grasp_width, grip_height
from ptint_drake.worlds.pick.scene import hand_size


@dataclass(frozen=True)
class PlanSegment:
    """What one segment aims at: ``kind`` "part" (part ``index``'s simulated centre + ``offset``),
    "latched" (where part ``index`` was at the segment's start + ``offset``), "slot" (slot
    ``index``'s place pose + ``offset``, yaw ``yaw`` rad) or "bin" (bin ``index``'s drop point +
    ``offset``; ``yaw``: the part's declared yaw, for planning) or "belt" (outgoing belt ``index``'s
    place point at t = 0 + ``offset``, riding at ``ride`` m/s, yaw ``yaw``); ``task``, ``phase`` and
    ``attempt`` (0: the first approach and descend, 1…: a retry's backoff, approach, descend) name it."""

    task: int
    phase: str
    kind: str
    index: int
    offset: tuple
    yaw: float = 0.0
    attempt: int = 0
    ride: tuple = (0.0, 0.0, 0.0)  # m/s, world: a "belt" place's velocity (0: a fixed place)
    along: float = 0.0  # m: a "belt" place's coordinate along its belt at t = 0 (``task.belt_at``)
    grip: tuple = ()  # (yaw, symmetry) rad of a task with a chosen grip (``aimed_yaw``); () none


VIA_PART, VIA_SLOT = "via_part", "via_slot"  # the kinds of a via segment (``Via``)


def aimed_yaw(part_yaw: float, grip: tuple) -> float:
    """rad: the yaw a segment aims the tool at for a part at ``part_yaw``: with a chosen grip
    (``PlanSegment.grip`` = (yaw, symmetry), ``PickTaskConfig.grip_yaw``) the part's yaw turned by
    whole ``symmetry`` periods nearest the chosen yaw — the chosen yaw itself where the symmetry is
    0 (a cylinder: any yaw) — so an estimate that moves less than half a period keeps the branch;
    ``part_yaw`` without one."""
    if not grip:
        return float(part_yaw)
    yaw, symmetry = grip
    if symmetry <= 0.0:
        return float(yaw)
    return float(part_yaw + symmetry * np.rint((yaw - part_yaw) / symmetry))
# the kinds of a place target (``place_target``): a tray slot, a bin, or an outgoing belt (riding it)
PLACES = ("slot", "bin", "belt")


@dataclass(frozen=True)
class Via:
    """A fixed point on the way of task ``task``'s ``phase`` ("approach": its first attempt's, or
    "carry"): a segment of its own (phase ``via``, kind ``via_part`` before an approach: the tool
    turned as part ``index`` is; ``via_slot`` before a carry: turned to the slot's yaw) aims at
    ``position`` (world, m) for the fraction ``share`` of the phase's tf (the phase's
    ``MoveConfig.via_share`` instead where it gives one: a line's task, ``line.via_split``), the
    phase the rest;
    ``yaw`` (rad; before a carry only): the tool's yaw there instead of the slot's (the way the
    wrist turns: ``route``)."""

    task: int
    phase: str
    position: tuple
    share: float
    yaw: Optional[float] = None


@dataclass(frozen=True)
class Replan:
    """What a run decided for one task (``worlds.pick.world``): the start of each retry (its
    backoff, s), how long the lift of the last attempt waits beyond its planned start for the
    grasp to be confirmed (s), and ``abort``: when the last attempt, found without a part and
    with no retry left, backs off (s; None: it did not) — the fingers open and the tool rises
    ``clearance`` before the task's lift, carry, place and retreat go on with an empty hand."""

    retries: tuple = ()
    lift_delay: float = 0.0
    abort: Optional[float] = None


@dataclass(frozen=True)
class Attempt:
    """One approach and descend of a task: its approach's start, its close command's time, its
    prescribed grasp time (the descend's end) and the time its grasp is checked (the lift's
    planned start: grasp + dwell + the lift's delay, or the next retry's start)."""

    start: float
    close: float
    grasp: float
    check: float


@dataclass(frozen=True)
class PickPlan:
    """The schedule, one ``PlanSegment`` per segment, the gripper's commands [(t, opening)], the
    expected part widths [(t, m)], and per task the close command's time and the prescribed
    grasp time of its last attempt, and all its ``attempts``."""

    schedule: Schedule
    segments: tuple
    commands: tuple
    close_times: tuple
    grasp_times: tuple
    end: float
    widths: tuple = ()
    attempts: tuple = ()

    def segment_index(self, task: int, phase: str, attempt: int = -1) -> int:
        """The index in the schedule of task ``task``'s segment ``phase`` (one of PHASES, or
        "backoff"); for an approach or a descend, that of ``attempt`` (-1: the last)."""
        found = [i for i, s in enumerate(self.segments) if s.task == task and s.phase == phase]
        return found[attempt if phase in ("approach", "descend", "backoff") else 0]


def _up(h: float) -> tuple:
    return (0.0, 0.0, h)


def _task_segments(k: int, task: PickTaskConfig, part: int, place: tuple, start: float, replan: Replan,
                   hold: float = 0.0, vias: tuple = (), ride: tuple = (0.0, 0.0, 0.0), grip: tuple = (),
                   above: float = 0.0):
    """The segments of task k, their plan entries, the attempts' (start, grasp) and the end;
    ``place``: (kind, index, yaw) of its place target (``place_target``); ``hold``: how long the
    first attempt waits at its pre-grasp pose before its descend (s); ``vias``: the task's ``Via``
    (at most one per phase); ``ride``: its place's velocity (m/s, an outgoing belt's); ``grip``:
    every segment's ``PlanSegment.grip``; ``above``: how far above the part's centre the tool grips
    it (m, ``config.grip_height``): every offset from the part, and from its place, is raised by it."""
    segments, plans, attempts = [], [], []
    routes = {v.phase: v for v in vias if v.task == k}

    def add(phase, kind, index, offset, yaw, t, attempt=0, until=np.inf):
        move = getattr(task, phase)
        tf = min(move.tf, until - t)  # a descend cut short by its retry (the grasp found empty)
        end = t + tf
        via = routes.get(phase) if attempt == 0 else None
        if via is not None:  # the way around the base: the phase's tf shared by the via and the phase
            share = via.share if move.via_share is None else move.via_share
            segments.append(Segment(t, share * tf, move.beta))
            plans.append(PlanSegment(k, "via", VIA_PART if phase == "approach" else VIA_SLOT,
                                     index, tuple(float(c) for c in via.position),
                                     yaw if via.yaw is None else float(via.yaw), attempt, grip=grip))
            t, tf = t + share * tf, end - (t + share * tf)  # (its end: t + tf, as without a via)
        segments.append(Segment(t, tf, move.beta))
        belt = kind == "belt"
        plans.append(PlanSegment(k, phase, kind, index, offset, yaw, attempt,
                                 ride if belt else (0.0, 0.0, 0.0), task.belt_at if belt else 0.0, grip))
        return end

    t = start
    retries = replan.retries
    high = _up(task.clearance + above)  # the pre-grasp pose, a backoff's and the retreat's
    for attempt in range(len(retries) + 1):
        if attempt:
            t = add("backoff", "latched", part, high, 0.0, retries[attempt - 1], attempt)
        approach = t
        t = add("approach", "part", part, high, 0.0, t, attempt)
        if attempt == 0:
            t += hold
        grasp = t + task.descend.tf  # prescribed, even where the descend is cut short
        last = replan.abort if replan.abort is not None else np.inf
        if attempt < len(retries) or last > t + 1e-9:  # an abort at the descend's start: none
            t = add("descend", "part", part, _up(above), 0.0, t, attempt,
                    retries[attempt] if attempt < len(retries) else last)
        attempts.append((approach, grasp))
    if replan.abort is not None:
        t = add("backoff", "latched", part, high, 0.0, replan.abort, len(retries))
        t -= task.dwell  # the lift right after it
    t = add("lift", "latched", part, _up(task.lift_height + above), 0.0, t + task.dwell + replan.lift_delay)
    kind, index, yaw = place
    dx, dy = (float(c) for c in task.bin_at) if kind == "bin" else (0.0, 0.0)  # (over the bin's floor)
    t = add("carry", kind, index, (dx, dy, task.lift_height + above), yaw, t)
    t = add("place", kind, index, (dx, dy, above), yaw, t)
    t = add("retreat", kind, index, (dx, dy, high[2]), yaw, t + task.dwell)
    return segments, plans, attempts, t


def pick_plan(pick: PickConfig, replans: tuple = (), vias: tuple = ()) -> PickPlan:
    """The plan of the ``pick`` block (``check_tasks`` first for one-line errors), with the
    retries and lift delays a run decided (``replans``: one ``Replan`` per task, none: the plan
    before the run) and the ways around the base (``vias``: ``Via``, ``route.routed_plan``)."""
    names = [p.name for p in pick.parts]
    reach = hand_size(pick.gripper.model)[0] if pick.tasks else 0.0
    segments, plans, commands, closes, grasps, widths, attempts = [], [], [], [], [], [], []
    t = 0.0
    commands.append((0.0, pick.gripper.initial_opening))
    for k, task in enumerate(pick.tasks):
        replan = replans[k] if k < len(replans) else Replan()
        part = names.index(task.part)
        start = max(task.start, t) if task.start > 0.0 else t
        width = grasp_width(pick.parts[part])
        opening = width + task.margin
        first_close, hold = _closed_on_nothing(pick, task, start)
        grip = () if task.grip_yaw is None else (float(task.grip_yaw), part_symmetry(pick.parts[part]))
        segs, plan, tries, t = _task_segments(k, task, part, place_target(pick, task), start, replan, hold,
                                              vias, place_ride(pick, task), grip,
                                              grip_height(pick.parts[part], reach))
        widths.append((tries[0][0], width))
        task_attempts = []
        for j, (approach, grasp) in enumerate(tries):
            close = _planned_close(grasp, task, pick.gripper.speed)
            if j == 0 and first_close is not None:
                close = first_close  # the test option (PickConfig.test_close_advance_s)
            commands.append(((replan.retries[j - 1] if j else approach), opening))
            if not (j == len(replan.retries) and replan.abort is not None and replan.abort <= close):
                commands.append((close, 0.0))  # (an abort before the close: no grasp is attempted)
            check = replan.retries[j] if j < len(replan.retries) else grasp + task.dwell + replan.lift_delay
            if j == len(replan.retries) and replan.abort is not None:
                check = replan.abort
                commands.append((replan.abort, opening))
            task_attempts.append(Attempt(approach, close, grasp, check))
        place = [p.phase for p in plan].index("place")
        commands.append((segs[place].end, opening))
        segments += segs
        plans += plan
        closes.append(task_attempts[-1].close)
        grasps.append(task_attempts[-1].grasp)
        attempts.append(tuple(task_attempts))
    return PickPlan(Schedule(segments), tuple(plans), tuple(commands), tuple(closes), tuple(grasps), t,
                    tuple(widths), tuple(attempts))


def place_target(pick: PickConfig, task: PickTaskConfig) -> tuple:
    """(kind, index, yaw) of a task's place target: ("slot", the slot, its yaw on the tray), or
    ("bin", the bin, the part's declared yaw: the tool keeps the yaw it grasped at, and the targets
    read it off the part at the lift, ``targets.PickTargets``), or ("belt", the outgoing belt, the
    yaw that turns the part's closing axis across the belt — of the two, the one nearer the part's
    declared yaw: the open fingers stand beside it across the belt, never towards the parts before
    and after it on the belt) (rad)."""
    if task.belt:
        index = [b.name for b in pick.belts].index(task.belt)
        d = pick.belts[index].direction
        across = float(np.arctan2(d[1], d[0])) + 0.5 * np.pi
        declared = next(p.yaw_deg for p in pick.parts if p.name == task.part)
        yaw = float(np.radians(declared)) if isinstance(declared, (int, float)) else across
        return "belt", index, across + np.pi * round((yaw - across) / np.pi)
    if task.bin:
        yaw = next(p.yaw_deg for p in pick.parts if p.name == task.part)
        index = [b.name for b in pick.bins].index(task.bin)
        return "bin", index, float(np.radians(yaw)) if isinstance(yaw, (int, float)) else 0.0
    if task.place_yaw is not None:  # (a line's decision: the slot's yaw by the part's symmetry)
        return "slot", task.slot, float(task.place_yaw)
    return "slot", task.slot, float(np.radians(pick.tray.yaw_deg + pick.tray.slots[task.slot].yaw_deg))


def part_symmetry(part) -> float:
    """rad: a part's yaw symmetry about the vertical (``part_fit.yaw_symmetry``: π/2 for a
    square-topped box, π for another box, 0 — any — for a cylinder)."""
    return yaw_symmetry(part.shape, part.size)


def place_ride(pick: PickConfig, task: PickTaskConfig) -> tuple:
    """m/s (world): the velocity of a task's place target — its outgoing belt's declared speed along
    its direction (the planning scenario's: a line's driver puts there what the controller side
    knows), 0 for a slot or a bin."""
    if not task.belt:
        return (0.0, 0.0, 0.0)
    belt = next(b for b in pick.belts if b.name == task.belt)
    d = np.asarray(belt.direction, dtype=float)
    return tuple(float(c) for c in belt.speed * d / np.linalg.norm(d))


def _planned_close(grasp: float, task: PickTaskConfig, speed: float) -> float:
    """When the close command goes out for a grasp at ``grasp``: the fingers meet the part (half
    the ``margin`` at ``speed`` each) at the prescribed time, shifted by ``close_delay``."""
    return grasp - 0.5 * task.margin / speed + task.close_delay


SETTLE_BEFORE_DESCEND = 0.02  # s: the held arm descends this long before the fingers close past the part


def _closed_on_nothing(pick: PickConfig, task: PickTaskConfig, start: float) -> tuple:
    """The test option ``pick.test_close_advance_s`` = a on a task's first attempt: (its close
    command's time, how long the arm holds its pre-grasp pose before the descend); (None, 0) if a = 0.

    a > 0 ("closed on nothing"): the close command comes a earlier than the plan would send it,
    and the arm waits at its pre-grasp pose, ``clearance`` above the part, until the fingers have
    all but closed past the part's width (``margin`` + ``width_tolerance`` at twice the jaw speed,
    less ``SETTLE_BEFORE_DESCEND``), so that they close on nothing above the part whatever the
    clearance and the descend's tf.  Without the hold, on conveyor_pick_place (clearance 40 mm,
    descend 0.5 s) a close 0.3 s early finished just as the descending pads met the part's top
    face, whose friction stopped them 2.6 mm inside the part's width (within the tolerance): the
    gripper read ``holding`` on the part's top edges (docs/pick_place.md).  a < 0: the close
    comes |a| later, the arm does not wait (a late grasp).  A close merely early, the fingers still
    reaching the part, is ``tasks[k].close_delay`` < 0."""
    advance = pick.test_close_advance_s
    if advance == 0.0:
        return None, 0.0
    approach_end = start + task.approach.tf
    speed = pick.gripper.speed
    close = _planned_close(approach_end + task.descend.tf, task, speed) - advance
    if advance < 0.0:
        return close, 0.0
    closed = close + (task.margin + pick.width_tolerance) / (2.0 * speed)
    return close, max(0.0, closed - SETTLE_BEFORE_DESCEND - approach_end)


def _check_place(pick: PickConfig, task: PickTaskConfig, where: str) -> None:
    """ScenarioError unless the task names exactly one place: a slot of the tray, a bin or a belt."""
    if (task.slot is not None) + bool(task.bin) + bool(task.belt) != 1:
        raise ScenarioError(f"{where}.slot: give exactly one of slot (a tray slot), bin (a bin's name) and "
                            f"belt (an outgoing belt's name), got slot {task.slot}, bin {task.bin!r}, "
                            f"belt {task.belt!r}")
    if task.belt and task.belt not in [b.name for b in pick.belts]:
        raise ScenarioError(f"{where}.belt: no belt named {task.belt!r} in pick.belts")
    if task.bin and task.bin not in [b.name for b in pick.bins]:
        raise ScenarioError(f"{where}.bin: no bin named {task.bin!r} (bins: "
                            f"{', '.join(b.name for b in pick.bins) or 'none'})")
    size = next((b.size for b in pick.bins if b.name == task.bin), [])
    if task.bin and not (len(task.bin_at) == 2 and all(abs(c) <= h / 2 for c, h in zip(task.bin_at, size))):
        raise ScenarioError(f"{where}.bin_at: {list(task.bin_at)} m is not an (x, y) over the floor of "
                            f"bin {task.bin!r} (from its centre, within half its inner size)")
    if task.slot is not None and not (isinstance(task.slot, int) and 0 <= task.slot < len(pick.tray.slots)):
        raise ScenarioError(f"{where}.slot: {task.slot} is not a slot of the tray "
                            f"({len(pick.tray.slots)} slots)")


def check_tasks(pick: PickConfig) -> None:
    """ScenarioError naming the first bad field of the tasks."""
    names = [p.name for p in pick.parts]
    if not pick.tasks:
        raise ScenarioError("pick.tasks: at least one task is needed")
    if len(set(names)) != len(names):
        raise ScenarioError("pick.parts: part names must be unique")
    if not (isinstance(pick.retries, int) and 0 <= pick.retries <= 5):
        raise ScenarioError(f"pick.retries: an integer 0 … 5, got {pick.retries}")
    for name in ("grasp_window", "width_tolerance"):
        if not (getattr(pick, name) > 0.0 and np.isfinite(getattr(pick, name))):
            raise ScenarioError(f"pick.{name}: must be positive, got {getattr(pick, name)}")
    if not -1.0 <= pick.test_close_advance_s <= 1.0:
        raise ScenarioError(f"pick.test_close_advance_s: a test option in [-1, 1] s, "
                            f"got {pick.test_close_advance_s}")
    t = 0.0
    for k, task in enumerate(pick.tasks):
        where = f"pick.tasks[{k}]"
        if task.part not in names:
            raise ScenarioError(f"{where}.part: no part named {task.part!r} (parts: {', '.join(names)})")
        _check_place(pick, task, where)
        for phase in (*PHASES, "backoff"):
            move = getattr(task, phase)
            if not (move.tf > 0.0 and np.isfinite(move.tf)):
                raise ScenarioError(f"{where}.{phase}.tf: must be positive, got {move.tf}")
            if not 0.0 < move.beta < 1.0:
                raise ScenarioError(f"{where}.{phase}.beta: must be in (0, 1), got {move.beta}")
            if move.via_share is not None and not 0.0 < move.via_share < 1.0:
                raise ScenarioError(f"{where}.{phase}.via_share: must be in (0, 1), got {move.via_share}")
        for name in ("clearance", "lift_height", "dwell", "margin"):
            if not getattr(task, name) > 0.0:
                raise ScenarioError(f"{where}.{name}: must be positive, got {getattr(task, name)}")
        if 0.0 < task.start < t:
            raise ScenarioError(f"{where}.start: {task.start} s is before the previous task ends ({t:.3g} s)")
        t = max(t, task.start) + sum(getattr(task, p).tf for p in PHASES) + 2 * task.dwell
        if task.margin > 0.5 * task.descend.tf * pick.gripper.speed * 2:
            need = task.margin / (2 * pick.gripper.speed)
            raise ScenarioError(f"{where}.margin: the fingers need {need:.3g} s "
                                f"to close {task.margin} m, longer than half the descend")
