"""What a line achieved (metrics.json ``line``), from the truth (the probe's log of every part)
and the run's records — the parts, not the tasks, are counted:

- ``entered``: pool parts that came into the arm's reach (the pose sensor's line: its part's
  centre, resting on its belt, at or past the start of its reach window, ``view.window`` — the
  same Drake IK the scheduler uses); ``placed``: those a task placed (``picks[*].placed``: held
  at the place and within ``criteria.place_mm`` / ``place_deg`` at the end);
- per part (``parts``): its kind, release time, whether it entered and was placed, its task, its
  ``destination`` (``slot j``, ``bin <name>`` or ``belt <name>``: an outgoing belt) and,
  entered but not placed, a ``reason``: its task's failure (the pick verdict's codes, e.g.
  ``collision with <body>``, ``dropped``, ``missed after retry``, ``not placed``), or for a part
  no task took, the scheduler's last word on it (``not reachable in time``, ``blocked``, ``tray
  full``), ``passed unpicked`` (taken off past the belt's end, never looked at: the arm busy
  throughout) or ``on the belt at the end``, and when it was lost (``failed_at``: the last
  decision that skipped it, else the run's end; the timeline's cross);
- ``placed_fraction`` (placed / entered), ``picks_per_minute`` (placed / duration),
  ``cycle_s`` (per task: its approach's start to its retreat's end) and their mean;
  ``tasks_span_s`` (the first approach's start to the last retreat's end) and
  ``tasks_per_minute_busy`` (the tasks over it: on a surplus line, the arm's saturated
  throughput); ``planning_ms``: the wall time of the decisions that chose (the scheduler, the
  reach windows, the min-tf model of ``line.cycle``), median and max;
- ``decisions``: the decision log (``scheduler.Decision.record``, and the re-decisions);
- ``replaced``: the tasks replaced in their approach, each with the commanded torque's jump at
  the switch (N·m, the largest joint's change between the logged samples around it) beside the
  run's largest sample-to-sample change outside any switch; ``abandoned``: the same of the tasks
  given up in their approach (``give_up``: the arm sent to a hold, the part ``not reachable in
  time``);
- ``tracking``: the pose sensor's identities are the sensor's (no association, no IDSW to count).

With the rgbd camera (``seen``) the parts are counted by what the camera could see:

- ``entered``: the part's centre, resting on its belt, inside the camera's view (its frustum and
  depth range, ``rgbd_camera.in_view``: the geometry, whether or not a fit was made) at some
  sample every ``VIEW_SAMPLE``; a part that reached the arm's reach window without entering the
  view is not counted and is named ``not seen`` (``not_seen``: their count), as is a part that
  entered and no track ever took a fit of;
- ``tracking`` (``part_tracks.track_metrics`` against the truth: each frame's fits matched to
  the nearest simulated part, from the probe's log): ``idsw`` (must be 0), the tracks of each
  part, the parts of each track; the scheduler's skips of a part are those of its tracks;
- per part ``seen``: the stamp of the first frame a track took a fit of it (the pose sensor's
  line: its release, the sensor reports it from then on; never: None);
- ``classes``: the catalog's kinds in order (name, height): what a track's class (the tracks log's
  column, ``track_system``) is, for the replay's markers.
"""

from __future__ import annotations

import numpy as np

from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose, in_view
from ptint_drake.verdict.metrics import Reason
from ptint_drake.worlds.pick.metrics import pick_reasons
from ptint_drake.worlds.pick.part_tracks import frame_matches, frame_stamps, track_metrics
from ptint_drake.worlds.pick.probe import PART_WIDTH
from ptint_drake.worlds.pick.scene import belt_frame, part_shape

VIEW_SAMPLE = 10  # probe samples (``cell.PROBE_PERIOD`` each) between the view checks of ``entered``


def _on_belt(scenario, probe: np.ndarray, k: int) -> tuple:
    """(the part's centres in its belt's frame, which samples rest on the belt, those in world)."""
    part = scenario.pick.parts[k]
    belt = {b.name: b for b in scenario.pick.belts}[part.belt]
    world = probe[:, PART_WIDTH * k: PART_WIDTH * k + 3]
    local = belt_frame(belt).inverse().multiply(world.T).T
    on = (np.abs(local[:, 1]) <= belt.width / 2) & (np.abs(local[:, 2] - part_shape(part)[1] / 2) < 0.01)
    return local, on, world


def _entered(scenario, view, probe: np.ndarray, k: int) -> bool:
    """Into the arm's reach window (the pose sensor's line; module docstring)."""
    local, on, _ = _on_belt(scenario, probe, k)
    if not np.any(on):
        return False
    belt = scenario.pick.parts[k].belt
    s_in, _ = view.window_at(belt, float(np.median(local[on, 1])), float(np.median(local[on, 2])))
    return bool(np.any(local[on, 0] >= s_in))


def _in_view(scenario, probe: np.ndarray, k: int) -> bool:
    """Into the camera's view, resting on its belt (module docstring)."""
    _, on, world = _on_belt(scenario, probe[::VIEW_SAMPLE], k)
    camera = scenario.measurement.camera
    return bool(np.any(on) and np.any(in_view(camera_pose(camera), camera_info(camera), world[on])))


def camera_tracking(scenario, series: dict) -> tuple[dict, dict]:
    """With the camera: ``tracking`` (module docstring) and per part the stamp it was first seen."""
    t, probe = series["t"], series["probe"]
    log = (series["tracks_t"], series["tracks"])
    truth = [(t, probe[:, PART_WIDTH * k: PART_WIDTH * k + 3]) for k in range(len(scenario.pick.parts))]
    seen: dict = {}
    frames, _ = frame_matches(log, truth)
    for stamp, frame in zip(frame_stamps(log), frames):
        for part, _track in frame:
            seen.setdefault(part, stamp)
    return track_metrics(log, truth, [p.name for p in scenario.pick.parts]), seen


def _unpicked_reason(ids: list, decisions: list, passed: bool) -> str:
    last = None
    for d in decisions:
        for skip in d.get("skipped", []):
            if skip["track"] in ids:
                last = skip["reason"]
    if last is None or last == "later deadline":
        return "passed unpicked" if passed else "on the belt at the end"
    return "blocked" if last.startswith("blocked") else last


def _last_skipped(ids: list, decisions: list):
    """The time of the last decision that skipped one of tracks ``ids`` (None: none did)."""
    times = [d["t"] for d in decisions for skip in d.get("skipped", []) if skip["track"] in ids]
    return float(times[-1]) if times else None


def _torque_jumps(series: dict, replaced: list) -> tuple[list, float]:
    t, tau = series["t"], np.asarray(series["tau"])
    steps = np.max(np.abs(np.diff(tau, axis=0)), axis=1)
    near = np.zeros(len(steps), dtype=bool)
    rows = []
    for r in replaced:
        i = int(np.searchsorted(t, r["t"]))
        lo, hi = max(i - 1, 0), min(i + 1, len(t) - 1)
        near[max(lo - 1, 0):hi + 1] = True
        rows.append({"t": r["t"], "task": r["task"], "drift_mm": round(r["drift_mm"], 2),
                     "torque_jump_Nm": float(np.max(np.abs(tau[hi] - tau[lo])))})
    usual = float(np.max(steps[~near])) if np.any(~near) else 0.0
    return rows, usual


def line_metrics(scenario, driver, metrics: dict, series: dict) -> dict:
    """metrics.json ``line`` (module docstring); ``scenario``: the run's expanded copy."""
    probe = series["probe"]
    by_part = {p["part_index"]: (k, p) for k, p in enumerate(metrics["picks"])}
    codes = {}
    for k, code in pick_reasons(metrics["picks"]):
        codes.setdefault(k, code)
    truth, parts, camera = driver.truth, [], driver.view.camera
    tracking, seen = camera_tracking(scenario, series) if camera else (None, {})
    for r in driver.releases:
        k, name = r.part, scenario.pick.parts[r.part].name
        reached = k in truth.released and _entered(scenario, driver.view, probe, k)
        row = {"part": name, "kind": r.kind, "belt": r.belt, "released": r.t,
               "entered": k in truth.released and (_in_view(scenario, probe, k) if camera else reached),
               "seen": seen.get(k) if camera else (r.t if k in truth.released else None),
               "task": by_part[k][0] if k in by_part else None, "placed": False, "reason": None}
        if row["task"] is not None:
            pick = by_part[k][1]
            row["placed"] = bool(pick["placed"])
            row["destination"] = (f"belt {pick['belt']}" if "belt" in pick else f"bin {pick['bin']}"
                                  if "bin" in pick else f"slot {pick['slot']}")
        ids = tracking["tracks_per_part"].get(name, []) if camera else [k]
        if (row["entered"] or reached) and not row["placed"]:
            row["reason"] = (codes.get(row["task"], "not placed") if row["task"] is not None
                             else "not seen" if row["seen"] is None
                             else _unpicked_reason(ids, driver.decisions, k in truth.passed))
            if row["task"] is None:  # when it was lost: the last decision that skipped it, else the end
                row["failed_at"] = _last_skipped(ids, driver.decisions) or float(series["t"][-1])
        parts.append(row)
    entered = sum(p["entered"] for p in parts)
    placed = sum(p["placed"] for p in parts)
    plan = driver.built.plan
    cycles = [plan.schedule.segments[plan.segment_index(k, "retreat")].end
              - plan.schedule.segments[plan.segment_index(k, "approach", 0)].start
              for k in range(len(scenario.pick.tasks))]
    segments = plan.schedule.segments
    span = (segments[plan.segment_index(len(cycles) - 1, "retreat")].end
            - segments[plan.segment_index(0, "approach", 0)].start) if cycles else None
    jumps, usual = _torque_jumps(series, driver.replaced + driver.abandoned)
    times = 1e3 * np.asarray(driver.planning_s)
    return {"released": len(truth.released), "entered": entered, "placed": placed,
            "placed_fraction": placed / entered if entered else None,
            "picks_per_minute": 60.0 * placed / scenario.duration, "cycle_s": cycles,
            "mean_cycle_s": float(np.mean(cycles)) if cycles else None,
            "tasks_span_s": span, "tasks_per_minute_busy": 60.0 * len(cycles) / span if span else None,
            "planning_ms": {"decisions": len(times),
                            "median": float(np.median(times)) if len(times) else None,
                            "max": float(np.max(times)) if len(times) else None},
            "passed": len(truth.passed), "parts": parts, "decisions": driver.decisions,
            "replaced": jumps[:len(driver.replaced)], "abandoned": jumps[len(driver.replaced):],
            "largest_torque_step_elsewhere_Nm": usual,
            "not_seen": sum(p["reason"] == "not seen" for p in parts),
            "classes": [{"name": c.name, "height": float(part_shape(c)[1])}
                        for c in scenario.pick.line.catalog],
            "idsw": tracking["idsw"] if camera else None,
            "tracking": tracking or "pose sensor: identities are the sensor's (no association, no IDSW)"}


def line_reasons(line: dict) -> list[Reason]:
    """The verdict's reasons: every part that entered and was not placed, and every part not seen,
    with its reason; with the camera, identity switches (``idsw`` > 0)."""
    reasons = [Reason(None, p["reason"], f"{p['part']}: {p['reason']}") for p in line["parts"]
               if (p["entered"] or p["reason"] == "not seen") and not p["placed"]]
    if line.get("idsw"):  # the camera's tracks: a part's fits went to another track (must be 0)
        reasons.append(Reason(None, "identity switch", f"tracking: {line['idsw']} identity switches"))
    return reasons


def placed_collision_warnings(metrics: dict) -> list[str]:
    """A line's warnings (none without a line): one per part placed although its task's arm or
    gripper touched something on the way (``picks[*].collision_with``) — the line counts the part
    placed, the warning names what was hit (a task list's collision is a failure of its pick)."""
    out = []
    for p in metrics["line"]["parts"] if "line" in metrics else []:
        pick = metrics["picks"][p["task"]] if p["placed"] and p["task"] is not None else None
        if pick is not None and pick["collision"]:
            bodies = ", ".join(pick.get("collision_with") or []) or "a body not named"
            out.append(f"{p['part']}: placed, but its task's arm or gripper touched {bodies}")
    return out
