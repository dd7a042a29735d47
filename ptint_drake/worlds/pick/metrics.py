"""What a pick and place achieved: per segment the interception errors, per task the pick.

``segment_rows`` — per segment (``pick.tasks`` phases): |e| at its start and at its prescribed time
start + tf against what it aims at *then* (the part's simulated pose, the latched lift point or the
slot), and the tool's angle from the top-down grasp (deg).

``pick_metrics`` — metrics.json's ``"picks"``, one entry per task, from the probe's log
(``pick.probe``, every 2 ms: the plant's truth, never the controller's view) and the grasp
observer's log (``systems.hand.gripper.GraspObserver``: what the gripper sensed):

- ``attempts``: approaches and descends made (1 + retries); ``attempt_details``: per attempt its
  close command, prescribed grasp time, when its grasp state was read (``t_check``) and what it
  was (``state``), and the largest pad–part grip force until then (``peak_grip_force_N``);
  ``grasp_confirmed``: the last attempt's state was ``holding``; ``retry_refused``: why no
  (further) retry was planned ("out of retries", "out of reach …");
- ``t_grasp``: the first time both finger pads touch the part in the last attempt (None: never);
  ``t_holding``: the first time the gripper reported ``holding`` then;
- ``grasped``: the grasp was confirmed, and at the lift's start the part is squeezed between both
  pads (the grip force ≥ ``GRASP_FORCE``); ``grip_force_N``: the grip force then;
- grip force: the smaller of the two pads' contact forces on the part along the closing axis
  (``probe.grip_forces``), what squeezes it; ``peak_grip_force_N``: its largest value from the
  lift's start to the place's tf;
- ``held_at_place``: both pads touch the part at the place's tf; ``state_at_place``: the
  gripper's state then;
- ``slip_mm``: for a grasped part, its largest displacement relative to the tool frame from the
  lift's start to the place's tf while both pads touch it (None for a part never grasped);
- ``place_error_mm`` / ``place_error_deg``: the part's resting pose at the end of the run against
  its place pose (centre; the angle of the rotation between them, a box's half-turn about its
  vertical axis counted as the same pose, a cylinder's turn about its axis ignored);
- ``placed``: grasped, held at the place, and within ``criteria.place_mm`` and
  ``criteria.place_deg``; for a task into a bin (``bin``: its name, ``slot`` None) instead
  ``in_bin``: the part's final centre inside the bin's inner box, below its walls' top
  (``scene.in_bin``), with no mm criterion (its ``place_error_mm`` is from the drop point);
- ``collision``: a contact of the arm or the gripper with any part or belt during an approach or
  a descend before its close command, or any in ``collision_with``;
- ``collision_with``: the obstacles (belts, ``tray``, ``floor``, other parts; the own part touched
  by anything but the fingers) the arm or the gripper touched in the task's window
  (``collisions.pick_collisions``), and every body touched during an approach or a descend before
  its close command (``collisions.touched_before_close``: the own part too, fingers or not), so a
  ``collision`` always names its bodies;
- ``saturated_fraction``, ``joint_speed_ratio``, ``joint_speed_joint``, ``joint_speed_over_s``: the
  runaway tests of the task's window (``runaway.runaway_metrics``, added by the world after the
  series are made).

``tracking`` (with a camera) — the identity switches of the perception's tracks against the
truth (``part_tracks.track_metrics``: ``idsw`` must be 0).

``pick_reasons`` — the verdict's reasons: first a runaway in the task's window, ``pick k:
saturated`` and ``pick k: joint speed beyond limit`` (``runaway``); ``pick k: collision with
<body>``;
``pick k: empty grasp`` (the grasp never confirmed, no retry allowed: ``pick.retries: 0``) or
``pick k: missed after retry`` (retries spent, or the retry out of reach); otherwise ``pick k:
late grasp`` (t_grasp more than ``LATE_GRASP`` after the prescribed grasp time, or never),
``pick k: early grasp`` (more than ``EARLY_GRASP`` before it), ``pick k: dropped`` (grasped, not
in the hand at the place) or ``pick k: not placed`` (a bin's: ``pick k: not in the bin``).
"""

from __future__ import annotations

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from ptint_drake.systems.task.orientation import rotation_angle, tool_yaw, top_down_reference
from ptint_drake.worlds.pick.out_belt import on_belt
from ptint_drake.worlds.pick.collisions import pick_collisions, touched_before_close
from ptint_drake.worlds.pick.part_tracks import track_metrics
from ptint_drake.worlds.pick.probe import BELT, LEFT, OTHER, PART_WIDTH, RIGHT
from ptint_drake.worlds.pick.runaway import runaway_reasons
from ptint_drake.worlds.pick.scene import in_bin
from ptint_drake.worlds.pick.targets import turned
from ptint_drake.worlds.pick.tasks import PLACES

LATE_GRASP = 0.05  # s after the prescribed grasp time
EARLY_GRASP = 0.05  # s before it


def rotation_of(wxyz) -> np.ndarray:
    """The 3 × 3 rotation of a logged quaternion (w, x, y, z), through Drake's ``RotationMatrix``."""
    q = np.asarray(wxyz, dtype=float)
    return RotationMatrix(Quaternion(q / np.linalg.norm(q))).matrix()


def _aim(built, i: int, aims: dict, at_start: bool, t: float = 0.0):
    """(position, rotation 15) that segment i aims at, from the values at a stop."""
    seg = built.plan.segments[i]
    offset = np.asarray(seg.offset)
    if seg.kind in PLACES:  # a bin's: the rotation latched at the lift (targets.PickTargets)
        rot = np.zeros(15)
        rot[0:9] = (RotationMatrix.MakeZRotation(seg.yaw).matrix().ravel() if seg.kind != "bin"
                    else turned(aims["latched"][7:16], seg.grip))
        ride = np.asarray(seg.ride)  # (an outgoing belt's place rides it)
        return built.targets.places[i] + offset + ride * t, rot
    if seg.kind == "via_slot":  # a via (pick.route): a fixed point turned to a yaw (via_part: as its part)
        rot = np.zeros(15)
        rot[0:9] = RotationMatrix.MakeZRotation(seg.yaw).matrix().ravel()
        return offset, rot
    pose, rot = aims["parts"][seg.index]
    if seg.grip:  # a task's chosen grip turns its part's rotation (``targets.turned``)
        rot = np.r_[turned(rot[0:9], seg.grip), rot[9:15]]
    if seg.kind == "via_part":
        rot = rot.copy()
        rot[9:15] = 0.0
        return offset, rot
    if seg.kind == "latched":
        rot = rot.copy()
        rot[9:15] = 0.0
        base = pose[0:3] if at_start else aims["latched"][0:3]
        return base + offset, rot
    return pose[0:3] + offset, rot


def segment_rows(built, aims: dict) -> list:
    """Per segment: task, phase, start, tf, e0_norm, e_tf_norm (m), e_rot_tf_deg."""
    rows = []
    for i, (seg, plan) in enumerate(zip(built.plan.schedule.segments, built.plan.segments)):
        row = {"task": plan.task, "phase": plan.phase, "start": seg.start, "tf": seg.tf,
               "e0_norm": None, "e_tf_norm": None, "e_rot_tf_deg": None}
        for key, t, at_start in (("e0_norm", seg.start, True), ("e_tf_norm", seg.end, False)):
            if t not in aims:
                continue
            x, R = aims[t]["tool"]
            target, rot = _aim(built, i, aims[t], at_start, t)
            row[key] = float(np.linalg.norm(x - target))
            if key == "e_tf_norm":
                R_r = np.reshape(top_down_reference(rot, tool_yaw(R))[0:9], (3, 3))
                row["e_rot_tf_deg"] = float(np.degrees(rotation_angle(R, R_r)))
        rows.append(row)
    return rows


def _place_angle(R: np.ndarray, yaw: float, shape: str, size=(1.0, 0.0)) -> float:
    """deg from the slot's pose, folded by the part's symmetry about the vertical: any turn for a
    cylinder (the tilt only), 90° for a square-topped box, 180° for another box."""
    if shape == "cylinder":  # its turn about its own axis does not matter: the tilt only
        return float(np.degrees(np.arccos(np.clip(R[2, 2], -1.0, 1.0))))
    turns = (0.0, np.pi, 0.5 * np.pi, -0.5 * np.pi) if abs(size[0] - size[1]) < 1e-9 else (0.0, np.pi)
    return float(min(np.degrees(rotation_angle(R, RotationMatrix.MakeZRotation(yaw + turn).matrix()))
                     for turn in turns))


def _first(t: np.ndarray, mask: np.ndarray):
    hits = np.flatnonzero(mask)
    return float(t[hits[0]]) if len(hits) else None


GRASP_FORCE = 1.0  # N: the smaller pad force above which the part counts as squeezed


def _window(t: np.ndarray, a: float, b: float) -> np.ndarray:
    return (t >= a - 1e-9) & (t <= b + 1e-9)


def _at(t: np.ndarray, when: float) -> int:
    """The last sample at or before ``when``."""
    return min(max(int(np.searchsorted(t, when + 1e-9, side="right")) - 1, 0), len(t) - 1)


def _destination(built, k: int, part, end: np.ndarray, rest: np.ndarray, rest_t: float) -> tuple:
    """Task k's place as metrics: ({"slot": its slot}, {"slot": None, "bin", "in_bin"} or
    {"slot": None, "belt", "on_belt"}, {"place_error_mm", "place_error_deg"}) from the part's probe
    row at the end, ``end`` (an outgoing belt's: ``rest``, at its retreat's end ``rest_t``)."""
    plan = built.plan
    i = plan.segment_index(k, "place")
    into = plan.segments[i]
    box = built.station.config.bins[into.index] if into.kind == "bin" else None
    where = ({"slot": into.index} if box is None
             else {"slot": None, "bin": box.name, "in_bin": in_bin(box, end[0:3])})
    place = built.targets.places[i]
    if into.kind == "belt":  # judged at the retreat's end (``out_belt.on_belt``), riding
        belt, end = built.station.config.belts[into.index], rest
        judged = on_belt(belt, end[0:3], rotation_of(end[3:7]), part)
        where = {"slot": None, "belt": belt.name, "on_belt": judged, "belt_at": float(into.along)}
        place = place + np.asarray(into.ride) * rest_t
    return where, {"place_error_mm": float(1e3 * np.linalg.norm(end[0:3] - place)),
                   "place_error_deg": _place_angle(rotation_of(end[3:7]), into.yaw, part.shape, part.size)}


def _one_pick(built, k: int, logs: dict, outcome: dict) -> dict:
    from ptint_drake.systems.hand.gripper import GRASP_STATES, HOLDING  # noqa: PLC0415

    t, probe = logs["probe"]
    forces, states = logs["grip_forces"][1], logs["grasp_state"][1][:, 0]
    plan = built.plan
    attempts = plan.attempts[k]
    seg = {p: plan.schedule.segments[plan.segment_index(k, p)] for p in ("lift", "place")}
    part_index = plan.segments[plan.segment_index(k, "approach")].index
    part = built.station.config.parts[part_index]
    block = probe[:, PART_WIDTH * part_index: PART_WIDTH * (part_index + 1)]
    grip = np.min(forces[:, 2 * part_index: 2 * part_index + 2], axis=1)  # what squeezes it (N)
    last = attempts[-1]
    lift_start, place_end = seg["lift"].start, seg["place"].end
    both = (block[:, LEFT] > 0) & (block[:, RIGHT] > 0)
    t_grasp = _first(t, both & (t >= last.start))
    robot_flags = probe[:, [PART_WIDTH * j + c for j in range(len(built.station.parts))
                            for c in (LEFT, RIGHT, OTHER)] + [probe.shape[1] + BELT]]
    before = np.zeros(len(t), dtype=bool)
    for a in attempts:  # each approach and descend until its close command
        before |= (t >= a.start) & (t < a.close)
    collision = bool(np.any(robot_flags[before] > 0))
    early = touched_before_close(built, logs, before) if collision else []
    i_lift, i_place = _at(t, lift_start), _at(t, place_end)
    checks = outcome["checks"][k]
    confirmed = bool(checks and checks[-1]["state"] == "holding")
    grasped = bool(confirmed and both[i_lift] and grip[i_lift] >= GRASP_FORCE)
    held_at_place = bool(both[i_place])
    carried = _window(t, lift_start, place_end) & both
    slip = None
    if grasped and np.any(carried):
        tool_p, tool_q = probe[:, -7:-4], probe[:, -4:]
        rel = np.array([rotation_of(tool_q[j]).T @ (block[j, 0:3] - tool_p[j])
                        for j in np.flatnonzero(carried)])
        slip = float(np.max(np.linalg.norm(rel - rel[0], axis=1)))
    in_carry = _window(t, lift_start, place_end)
    holding = np.flatnonzero((states == HOLDING) & _window(t, last.start, place_end))
    details = []
    for j, a in enumerate(attempts):
        t_check = checks[j]["t"] if j < len(checks) else a.check  # when the state was read
        span = _window(t, a.start, t_check)
        details.append({"t_close_command": a.close, "t_grasp_prescribed": a.grasp, "t_check": t_check,
                        "state": checks[j]["state"] if j < len(checks) else None,
                        "peak_grip_force_N": float(np.max(grip[span])) if np.any(span) else 0.0})
    rest_t = plan.schedule.segments[plan.segment_index(k, "retreat")].end
    where, error = _destination(built, k, part, block[-1], block[_at(t, rest_t)], rest_t)
    return {"part": part.name, "part_index": part_index, **where,
            "grasped": grasped, "t_grasp": t_grasp, "t_grasp_prescribed": last.grasp,
            "t_close_command": last.close, "attempts": len(attempts), "attempt_details": details,
            "grasp_confirmed": confirmed,
            "retry_refused": outcome["refused"][k],
            "t_holding": float(t[holding[0]]) if len(holding) else None,
            "state_at_place": GRASP_STATES[int(states[i_place])], "held_at_place": held_at_place,
            "grip_force_N": float(grip[i_lift]),
            "slip_mm": None if slip is None else 1e3 * slip,
            "peak_grip_force_N": float(np.max(grip[in_carry])) if np.any(in_carry) else 0.0,
            **error, "collision": collision, "collision_before_close": early}


def pick_metrics(scenario, built, logs: dict, segments: list, outcome: dict) -> dict:
    """metrics.json of a pick scenario: ``segments`` (``segment_rows``) and ``picks``; ``outcome``:
    the run's grasp checks per task and attempt, why a retry was refused, the run's end (s)."""
    picks = []
    for k in range(len(scenario.pick.tasks)):
        pick = _one_pick(built, k, logs, outcome)
        touched = set(pick_collisions(built, logs, k)) | set(pick.pop("collision_before_close"))
        # arm/gripper vs belts, tray, floor, parts; and whatever the open fingers touched before the close
        pick["collision_with"] = [name for name in built.station.obstacles if name in touched]
        pick["collision"] = bool(pick["collision"] or pick["collision_with"])
        within = (pick["in_bin"] if "bin" in pick  # a bin: in it, no mm criterion
                  else pick["on_belt"] if "belt" in pick  # an outgoing belt: on it (line.out_belt)
                  else pick["place_error_mm"] <= scenario.criteria.place_mm
                  and pick["place_error_deg"] <= scenario.criteria.place_deg)
        pick["placed"] = bool(pick["grasped"] and pick["held_at_place"] and within)
        picks.append(pick)
    out = {"scenario": scenario.name, "duration": outcome["end"], "segments": segments, "picks": picks}
    if "tracks" in logs and scenario.pick.line is None:  # a camera: the IDSW (part_tracks; a line: its own)
        out["tracking"] = track_metrics(logs["tracks"], [logs[f"part_true_{k}"] for k in range(len(
            scenario.pick.parts))], [p.name for p in scenario.pick.parts])
    return out


def pick_reasons(picks: list) -> list:
    """(task, code) of every pick that failed (module docstring)."""
    out = []
    for k, p in enumerate(picks):
        out += [(k, code) for code in runaway_reasons(p)]  # the runaway first: its consequences follow
        if p["collision"]:
            out.append((k, "collision with " + ", ".join(p["collision_with"]) if p.get("collision_with")
                        else "collision"))
        if p.get("retry_refused") in ("part not seen", "blocked"):  # (rgbd: not seen, or no room: no grasp)
            out.append((k, p["retry_refused"]))
            continue
        if not p["grasp_confirmed"]:
            alone = p["attempts"] == 1 and p["retry_refused"] == "out of retries"
            out.append((k, "empty grasp" if alone else "missed after retry"))
            continue
        if p["t_grasp"] is None or p["t_grasp"] > p["t_grasp_prescribed"] + LATE_GRASP:
            out.append((k, "late grasp"))
        elif p["t_grasp"] < p["t_grasp_prescribed"] - EARLY_GRASP:
            out.append((k, "early grasp"))
        if p["grasped"] and not p["held_at_place"]:
            out.append((k, "dropped"))
        elif not p["placed"]:
            out.append((k, "not in the bin" if "bin" in p else "not on the belt" if "belt" in p
                        else "not placed"))
    return out
