"""The watch of a line's committed task during its approach (issue 44): ``driver.LineDriver``
calls ``watch`` at every stop while a task (or a hold: ``give_up``) is under way.

While a task approaches (before its descend), the scheduler's finger rule is asked again first
(``crowded``: a part released or seen after the decision may now stand where an open finger will
be): crowded, the scheduler decides again from now, else the task is given up and its part named
``blocked``.  Then the grasp point predicted now is compared with
the committed one; beyond ``line.redecide_mm`` (a belt without an encoder running faster or
slower than declared: its speed is then learned from the track, ``view.LineView.learned``) the
scheduler's rule is checked again with that speed: the part in its window from the approach's
end to the committed grasp and the lift, and the min-tf model's approach and descend from the
tool's present point (``line.cycle.LineCycles.fits``) fitting between the approach's start (or
now, under way) and the grasp — measured without the first condition (the belt slowed to 0.3×,
tests/e2e): the approach kept aimed at a part still upstream of reach and the arm ran away.  Still
in it and time enough, the task goes on (the targets follow the track: ``kept``); else the
scheduler decides again from now and the task is replaced (``replaced``: an approach under way
restarts from the present state, its tf stretched to the new grasp time; one not started yet
starts at the model's lead before it); nothing to replace it with, a task whose part is out of
its window at the approach's end or at the lift's start (a dwell after the grasp) is given up
(``give_up``: ``abandoned``, the arm sent to a hold from its present state, the part ``not
reachable in time``), any other goes on (``nothing feasible: kept``).

A task kept (either way) is planned again at what the drift showed (``keep``): the controller
side's belief (``driver.LineDriver.planning``: every track where it is seen now, its belt at the
speed now known) is updated, the approach stays as the run follows it (``plan.Pin``: its via, its
tf; the grasp time does not change), and the phases after the grasp get the vias the plan makes at
that belief, each fitted to what its via's legs need (``LineCycles.detours``, ``via_split.fitted``
with the model's straight tfs of the decision); where that plan differs from the run's, the run is
rebuilt (the pick run's replan and resume: the approach goes on towards the same target).  The
phases after the grasp are at least the model's tfs from where the part is now (``ahead``, at the
task's grip and place yaws), not only those of the decision's belief: harsh ``line_assembly``
seeds 0-11 at 4c93d1b, a late carry of a kept task warned joint 1 at 1.34x (seed 1), 1.19x (6)
and 1.08x (3) its speed limit, and none with it; seed 2's joint 3 went from 1.02x to 1.08x; the
parts placed as before.  Where
the model finds no top-down posture along a phase at that yaw (``ahead`` in the log) the task goes
on as it was: giving it up then (tried) lost two parts in those twelve seeds that the run placed
(seeds 0 and 10: a descend at y = 0.10-0.13 m the controller made, tool yaw off), to save seed
13's, whose arm ran away in the carry (a 1.0 kg cube on links x1.39 at 2x belt speed: joint 5 at
16.7 rad/s against its 4, collisions): that runaway is not fixed.  The log's entry names the
phases planned anew (``replanned``) and their vias' legs (``via_tf``).
Measured before (7100bb4, ``ptint robust line_assembly --samples 1 --seed 22``): only the
committed point followed the track, the plan held the part where the decision had seen it, and
the carry's via — above where the lift was to end — was 78 mm from the lift's real end, a leg
planned at 0.106 s: joint 3 at 8.8 rad/s against its 3.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ptint_drake.worlds.pick.line.cycle import destination_place, kind_part, track_yaw
from ptint_drake.worlds.pick.line.give_up import REASON, hold_of, unserved
from ptint_drake.worlds.pick.line.grip import grip_axis
from ptint_drake.worlds.pick.line.plan import line_plan, pin_of, unpinned
from ptint_drake.worlds.pick.line.scheduler import blocker, drifted
from ptint_drake.worlds.pick.line.via_split import DETOUR_PASSES, fitted
from ptint_drake.worlds.pick.phase_time import NoTfFits, cycle_time, held_mass

__all__ = ["AFTER", "abandon", "ahead", "crowded", "has_encoder", "keep", "watch"]

AFTER = ("lift", "carry", "place", "retreat")  # the phases a kept task plans anew


def watch(driver, run, context, t: float) -> bool:
    """The last task's grasp point against the committed one, before its descend (module
    docstring); ``driver``: the run's ``LineDriver``.  True when the tasks changed."""
    k = len(driver.scenario.pick.tasks) - 1
    plan = run.built.plan
    if t >= plan.schedule.segments[plan.segment_index(k, "descend", 0)].start - 1e-9:
        return False
    track_id, grasp, point = driver.committed[k]
    tracks = driver.view.tracks(context, t)
    track = next((tr for tr in tracks if tr.id == track_id), None)
    if track is not None and (hit := crowded(driver, k, track, tracks, grasp, t)) is not None:
        return _blocked(driver, run, context, t, k, track, hit)
    drift = track is not None and drifted(track, grasp, point, t, 1e-3 * driver.line.redecide_mm)
    if not drift:
        return False
    if np.isfinite(track.measured) and not has_encoder(driver.line, track.belt):
        driver.view.learned[track.belt] = track.measured  # the belt's speed, as its track shows it
        track = replace(track, speed=track.measured)
    entry = {"t": round(t, 4), "task": k, "track": track_id, "drift_mm": round(1e3 * drift, 2),
             "speed": round(track.speed, 4)}
    task = driver.scenario.pick.tasks[k]
    begin, end = max(t, task.start), task.start + task.approach.tf  # the approach's (rest and) end
    window = driver.view.window(track)
    tool = driver._tool_now(driver._arm_q(context))  # (point, yaw)
    fits = not unserved(track, window, grasp, t, end, driver.timing.slack) \
        and driver.cycles.fits(track, begin, grasp, t, *tool, task.grip_yaw)
    if fits:
        # in reach from the approach's end to the lift (``scheduler``), the model's approach fits
        driver.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
        return keep(driver, run, context, t, k, track.kind,
                    entry | {"redecide": "kept"} | ahead(driver, t, k, track, tool))
    if driver._choose(run, context, t, replacing=k):
        driver.replaced.append({"t": t, "task": k, "drift_mm": 1e3 * drift})
        driver.decisions[-1]["redecide"] = "replaced"
        return True
    why = unserved(track, window, grasp, t, end, task.dwell)  # the lift's start out of reach too
    if why:  # given up (``give_up``)
        abandon(driver, run, context, t, k, track, entry | {"why": why})
        return True
    driver.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
    return keep(driver, run, context, t, k, track.kind,
                entry | {"redecide": "nothing feasible: kept"} | ahead(driver, t, k, track, tool))


def crowded(driver, k: int, track, tracks: list, grasp: float, t: float):
    """The id of a track (other than committed task k's ``track``) whose part the open fingers of
    task k's grasp at ``grasp`` would now hit (the scheduler's ``blocker`` at the task's grip yaw),
    or None: a part released or seen after the decision can arrive beside the one chosen (a 0.05
    m/s belt of 40 mm cans: the next two 45 mm behind it)."""
    axis = grip_axis(driver.scenario.pick.tasks[k].grip_yaw)
    return blocker(replace(track, axis=axis), tracks, grasp, t, driver.timing)


def _blocked(driver, run, context, t: float, k: int, track, hit: int) -> bool:
    """Task k, in its approach, now ``crowded`` by track ``hit``: the scheduler decides again from
    now (``replaced``), else the task is given up (``abandon``: the part ``blocked``).  True."""
    entry = {"t": round(t, 4), "task": k, "track": track.id, "drift_mm": 0.0, "blocked_by": hit}
    if driver._choose(run, context, t, replacing=k):
        driver.replaced.append({"t": t, "task": k, "drift_mm": 0.0})
        driver.decisions[-1]["redecide"] = "replaced: blocked"
        return True
    abandon(driver, run, context, t, k, track, entry | {"why": f"blocked (track {hit})"},
            reason=f"blocked (track {hit})")
    return True


def ahead(driver, t: float, k: int, track, tool: tuple) -> dict:
    """Raise committed task k's straight tfs after the grasp (``LineDriver.straight``, which
    ``refit`` stretches the phases to) to the min-tf model's for ``track`` as seen at ``t`` — its
    slot or bin, its grip and place yaws, its approach from the tool's present (point, yaw)
    ``tool``; {} done, else {"ahead": why not} for the log (``NoTfFits``: no top-down posture
    along a phase at that yaw, the task going on as it was).  An outgoing belt's riding place is
    not checked."""
    task = driver.scenario.pick.tasks[k]
    if task.slot is None and not task.bin:
        return {}
    pick = driver.scenario.pick
    kind = kind_part(pick, track.kind)
    place = destination_place(pick, task.bin or task.slot, kind)
    # over a bin the tool keeps the yaw it grasped at (a bin task has no place_yaw; a line's task
    # always has its grip_yaw: ``cycle.task_of``)
    put = task.grip_yaw if task.place_yaw is None else task.place_yaw
    try:
        cycle = cycle_time(driver.cycles.model, track.at(max(t, task.start), t),
                           track.speed * np.asarray(track.direction), place, put,
                           track_yaw(track), held_mass(driver.scenario, kind.mass),
                           task, *tool, grip=task.grip_yaw, put=put)
    except NoTfFits as error:
        return {"ahead": f"no tf fits from where it is now: {error}"}
    straight = driver.straight.setdefault(k, {})
    for phase in AFTER:
        straight[phase] = max(straight.get(phase, 0.0), cycle.phases[phase])
    return {}


def has_encoder(line, belt: str) -> bool:
    """Whether ``belt`` of the line block ``line`` has an encoder (its speed is then read)."""
    return any(b.name == belt and b.encoder for b in line.belts)


def abandon(driver, run, context, t: float, k: int, track, entry: dict, reason: str = REASON) -> None:
    """Task k (the last, in its approach) given up (``give_up``): out of the run's tasks, its
    part named in the log (``reason``: the part's failure), and a ``Hold`` from the arm's present
    state after the tasks."""
    q = driver._arm_q(context)
    hold = hold_of(t, *driver._tool_now(q), np.asarray(track.position), lambda x: driver.view.reachable(x, q))
    for records in (driver.scenario.pick.tasks, run.replans, run.checks, run.refused):
        del records[k]
    run.replans[:] = unpinned(run.replans, k)
    del driver.committed[k]
    driver.straight.pop(k, None)
    for record in driver.decisions:  # its choice no longer names a task of the run (k is the next one's)
        if record.get("task") == k:
            record["task"], record["given up"] = None, round(t, 4)
    run.replans.append(hold)  # after the tasks' ``Replan`` entries (``plan.line_plan``)
    driver.given_up.add(track.id)
    driver.abandoned.append({"t": t, "task": k, "drift_mm": entry["drift_mm"]})
    driver.decisions.append(entry | {"redecide": "abandoned", "hold": [round(c, 4) for c in hold.position],
                                     "skipped": [{"track": track.id, "reason": reason}]})


def keep(driver, run, context, t: float, k: int, kind: str, entry: dict) -> bool:
    """Task k kept after a drift at ``t`` (module docstring): the belief updated, the approach
    pinned, the phases after the grasp planned anew (``refit``); ``entry`` logged with what was;
    True (a rebuild) where the plan of those phases changed."""
    driver._believe(driver.view.tracks(context, t), t)
    old = run.built.plan
    run.replans[:] = [*unpinned(run.replans, k), pin_of(old, k)]
    mass = held_mass(driver.scenario, driver.line.kind(kind).mass)
    task, needs, why = refit(driver, run, k, mass)
    driver.scenario.pick.tasks[k] = task
    new = line_plan(driver.planning(), tuple(run.replans), driver.built.arm)
    changed = [p for p in AFTER if _way(old, k, p) != _way(new, k, p)]
    entry |= {"replanned": changed, "via_tf": {p: [round(v, 3) for v in legs[:2]] for p, legs in needs.items()
                                               if p in AFTER}}
    entry |= {"tf": {p: round(getattr(task, p).tf, 3) for p in changed}} if changed else {}
    driver.decisions.append(entry | ({"why": why} if why else {}))
    return bool(changed)


def refit(driver, run, k: int, mass: float) -> tuple:
    """(task k, the needs of its vias, why not fitted or "") with its phases after the grasp
    fitted to the vias of the plan the run will follow (``LineCycles.detours`` on
    ``plan.line_plan``, ``via_split.fitted`` against the model's straight tfs of its decision,
    ``DETOUR_PASSES`` at most: a via may depend on the tf); ``mass`` (kg) held on its carry."""
    tasks = driver.scenario.pick.tasks
    task, needs = tasks[k], {}
    straight = {p: tf for p, tf in driver.straight.get(k, {}).items() if p in AFTER}
    for _ in range(DETOUR_PASSES):
        scenario = driver.planning()
        scenario = replace(scenario, pick=replace(scenario.pick, tasks=[*tasks[:k], task, *tasks[k + 1:]]))
        try:
            needs = driver.cycles.detours(scenario, line_plan(scenario, tuple(run.replans), driver.built.arm),
                                          k, mass)
        except NoTfFits as error:
            return task, {}, f"no tf fits a via's leg: {error}"
        short = fitted(task, {p: legs for p, legs in needs.items() if p in AFTER}, straight)
        if not short:
            return task, needs, ""
        task = replace(task, **short)
    return task, needs, f"the plan's vias still ask for more after {DETOUR_PASSES} passes"


def _way(plan, k: int, phase: str) -> tuple:
    """Task k's ``phase`` in ``plan`` with its via if any: each segment's tf, kind, point and yaw
    (rounded to 1e-9; not its start, which a phase before it moves)."""
    i = plan.segment_index(k, phase)
    first = i - 1 if plan.segments[i - 1].task == k and plan.segments[i - 1].phase == "via" else i
    return tuple((round(plan.schedule.segments[j].tf, 9), plan.segments[j].kind,
                  tuple(round(c, 9) for c in plan.segments[j].offset), round(plan.segments[j].yaw, 9))
                 for j in range(first, i + 1))
