"""The watch of a line's committed task during its approach (issue 44): ``driver.LineDriver``
calls ``watch`` at every stop while a task (or a hold: ``give_up``) is under way.

While a task approaches (before its descend), the grasp point predicted now is compared with
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
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ptint_drake.worlds.pick.line.give_up import REASON, hold_of, unserved
from ptint_drake.worlds.pick.line.scheduler import drifted

__all__ = ["abandon", "has_encoder", "watch"]


def watch(driver, run, context, t: float) -> bool:
    """The last task's grasp point against the committed one, before its descend (module
    docstring); ``driver``: the run's ``LineDriver``.  True when the tasks changed."""
    k = len(driver.scenario.pick.tasks) - 1
    plan = run.built.plan
    if t >= plan.schedule.segments[plan.segment_index(k, "descend", 0)].start - 1e-9:
        return False
    track_id, grasp, point = driver.committed[k]
    track = next((tr for tr in driver.view.tracks(context, t) if tr.id == track_id), None)
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
    if not unserved(track, window, grasp, t, end, driver.timing.slack) \
            and driver.cycles.fits(track, begin, grasp, t, *driver._tool_now(driver._arm_q(context)),
                                   task.grip_yaw):
        # in reach from the approach's end to the lift (``scheduler``), the model's approach fits
        driver.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
        driver.decisions.append(entry | {"redecide": "kept"})
        return False
    if driver._choose(run, context, t, replacing=k):
        driver.replaced.append({"t": t, "task": k, "drift_mm": 1e3 * drift})
        driver.decisions[-1]["redecide"] = "replaced"
        return True
    why = unserved(track, window, grasp, t, end, task.dwell)  # the lift's start out of reach too
    if why:  # given up (``give_up``)
        abandon(driver, run, context, t, k, track, entry | {"why": why})
        return True
    driver.decisions.append(entry | {"redecide": "nothing feasible: kept"})
    driver.committed[k][2] = tuple(float(c) for c in track.at(grasp, t))
    return False


def has_encoder(line, belt: str) -> bool:
    """Whether ``belt`` of the line block ``line`` has an encoder (its speed is then read)."""
    return any(b.name == belt and b.encoder for b in line.belts)


def abandon(driver, run, context, t: float, k: int, track, entry: dict) -> None:
    """Task k (the last, in its approach) given up (``give_up``): out of the run's tasks, its
    part named in the log, and a ``Hold`` from the arm's present state after the tasks."""
    q = driver._arm_q(context)
    hold = hold_of(t, *driver._tool_now(q), np.asarray(track.position), lambda x: driver.view.reachable(x, q))
    for records in (driver.scenario.pick.tasks, run.replans, run.checks, run.refused):
        del records[k]
    del driver.committed[k]
    for record in driver.decisions:  # its choice no longer names a task of the run (k is the next one's)
        if record.get("task") == k:
            record["task"], record["given up"] = None, round(t, 4)
    run.replans.append(hold)  # after the tasks' ``Replan`` entries (``plan.line_plan``)
    driver.given_up.add(track.id)
    driver.abandoned.append({"t": t, "task": k, "drift_mm": entry["drift_mm"]})
    driver.decisions.append(entry | {"redecide": "abandoned", "hold": [round(c, 4) for c in hold.position],
                                     "skipped": [{"track": track.id, "reason": REASON}]})
