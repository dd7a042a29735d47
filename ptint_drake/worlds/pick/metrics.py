"""What a pick and place achieved: per segment the interception errors, per task the pick.

``segment_rows`` — per segment (``pick.tasks`` phases): |e| at its start and at its prescribed time
start + tf against what it aims at *then* (the part's simulated pose, the latched lift point or the
slot), and the tool's angle from the top-down grasp (deg).

``pick_metrics`` — metrics.json's ``"picks"``, one entry per task, from the probe's log
(``pick.probe``, every 2 ms) — the plant's truth, never the controller's view:

- ``t_grasp``: the first time both finger pads touch the part (None: never);
- ``grasped``: at the end of the lift the part is between both pads and off its belt (its centre
  more than half the lift height above where it was at the prescribed grasp time);
- ``slip_mm``: the part's largest displacement relative to the tool frame from the lift's start to
  the place's tf;
- ``peak_grip_force_N``: the largest mean squeeze of the two finger drives while carried;
- ``place_error_mm`` / ``place_error_deg``: the part's resting pose at the end of the run against
  its place pose (centre; the angle of the rotation between them, a box's half-turn about its
  vertical axis counted as the same pose, a cylinder's turn about its axis ignored);
- ``placed``: grasped, and within ``criteria.place_mm`` and ``criteria.place_deg``;
- ``collision``: a contact of the arm or the gripper with any part or belt from the task's start
  until the close command, or any in ``collision_with``;
- ``collision_with``: the obstacles (belts, ``tray``, ``floor``, other parts; the own part touched
  by anything but the fingers) the arm or the gripper touched in the task's window
  (``collisions.pick_collisions``).

``pick_reasons`` — the verdict's reasons, printed ``pick 0: dropped``, ``pick 1: not placed``,
``pick 2: collision with <body>`` and ``pick 0: late grasp`` (t_grasp more than ``LATE_GRASP`` after the
prescribed grasp time, the descend's start + tf, or never).
"""

from __future__ import annotations

import numpy as np
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from ptint_drake.worlds.pick.collisions import pick_collisions
from ptint_drake.worlds.pick.probe import BELT, LEFT, OTHER, PART_WIDTH, RIGHT
from ptint_drake.systems.orientation import rotation_angle, tool_yaw, top_down_reference

LATE_GRASP = 0.05  # s after the prescribed grasp time


def rotation_of(wxyz) -> np.ndarray:
    """The 3 × 3 rotation of a logged quaternion (w, x, y, z), through Drake's ``RotationMatrix``."""
    q = np.asarray(wxyz, dtype=float)
    return RotationMatrix(Quaternion(q / np.linalg.norm(q))).matrix()


def _aim(built, i: int, aims: dict, at_start: bool):
    """(position, rotation 15) that segment i aims at, from the values at a stop."""
    seg = built.plan.segments[i]
    offset = np.asarray(seg.offset)
    if seg.kind == "slot":
        rot = np.zeros(15)
        rot[0:9] = RotationMatrix.MakeZRotation(seg.yaw).matrix().ravel()
        return built.targets.places[i] + offset, rot
    pose, rot = aims["parts"][seg.index]
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
            target, rot = _aim(built, i, aims[t], at_start)
            row[key] = float(np.linalg.norm(x - target))
            if key == "e_tf_norm":
                R_r = np.reshape(top_down_reference(rot, tool_yaw(R))[0:9], (3, 3))
                row["e_rot_tf_deg"] = float(np.degrees(rotation_angle(R, R_r)))
        rows.append(row)
    return rows


def _place_angle(R: np.ndarray, yaw: float, shape: str) -> float:
    if shape == "cylinder":  # its turn about its own axis does not matter: the tilt only
        return float(np.degrees(np.arccos(np.clip(R[2, 2], -1.0, 1.0))))
    return float(min(np.degrees(rotation_angle(R, RotationMatrix.MakeZRotation(yaw + turn).matrix()))
                     for turn in (0.0, np.pi)))


def _first(t: np.ndarray, mask: np.ndarray):
    hits = np.flatnonzero(mask)
    return float(t[hits[0]]) if len(hits) else None


def _one_pick(built, k: int, t: np.ndarray, probe: np.ndarray, grip: np.ndarray, lift: float) -> dict:
    plan = built.plan
    segs = [(s, p) for s, p in zip(plan.schedule.segments, plan.segments) if p.task == k]
    part_index = segs[0][1].index
    part = built.station.config.parts[part_index]
    block = probe[:, PART_WIDTH * part_index: PART_WIDTH * (part_index + 1)]
    start, close, lift_end = segs[0][0].start, plan.close_times[k], segs[2][0].end
    lift_start, place_end = segs[2][0].start, segs[4][0].end
    both = (block[:, LEFT] > 0) & (block[:, RIGHT] > 0)
    t_grasp = _first(t, both & (t >= start))
    robot_flags = probe[:, [PART_WIDTH * j + c for j in range(len(built.station.parts))
                            for c in (LEFT, RIGHT, OTHER)] + [probe.shape[1] + BELT]]
    before = (t >= start) & (t < close)
    collision = bool(np.any(robot_flags[before] > 0))
    i_lift = max(int(np.searchsorted(t, lift_end, side="right")) - 1, 0)
    i_grasp = min(int(np.searchsorted(t, plan.grasp_times[k])), len(t) - 1)
    grasped = bool(both[i_lift] and block[i_lift, 2] > block[i_grasp, 2] + 0.5 * lift)
    carried = (t >= lift_start) & (t <= place_end)
    tool_p, tool_q = probe[:, -7:-4], probe[:, -4:]
    rel = np.array([rotation_of(tool_q[j]).T @ (block[j, 0:3] - tool_p[j]) for j in np.flatnonzero(carried)])
    slip = float(np.max(np.linalg.norm(rel - rel[0], axis=1))) if len(rel) else None
    squeeze = -np.mean(grip[carried], axis=1) if np.any(carried) else np.zeros(1)
    place = built.targets.places[plan.segment_index(k, "place")]
    place_yaw = segs[4][1].yaw
    R_end = rotation_of(block[-1, 3:7])
    return {"part": part.name, "part_index": part_index, "slot": segs[4][1].index, "grasped": grasped,
            "t_grasp": t_grasp, "t_grasp_prescribed": plan.grasp_times[k], "t_close_command": close,
            "slip_mm": None if slip is None else 1e3 * slip,
            "peak_grip_force_N": float(np.max(np.abs(squeeze))),
            "place_error_mm": float(1e3 * np.linalg.norm(block[-1, 0:3] - place)),
            "place_error_deg": _place_angle(R_end, place_yaw, part.shape),
            "collision": collision}


def pick_metrics(scenario, built, logs: dict, segments: list) -> dict:
    """metrics.json of a pick scenario: ``segments`` (``segment_rows``) and ``picks``."""
    t, probe = logs["probe"]
    _, grip = logs["grip_force"]
    picks = []
    for k, task in enumerate(scenario.pick.tasks):
        pick = _one_pick(built, k, t, probe, grip, task.lift_height)
        pick["collision_with"] = pick_collisions(built, logs, k)  # arm/gripper vs belts, tray, floor, parts
        pick["collision"] = bool(pick["collision"] or pick["collision_with"])
        pick["placed"] = bool(pick["grasped"] and pick["place_error_mm"] <= scenario.criteria.place_mm
                              and pick["place_error_deg"] <= scenario.criteria.place_deg)
        picks.append(pick)
    return {"scenario": scenario.name, "duration": scenario.duration, "segments": segments, "picks": picks}


def pick_reasons(picks: list) -> list:
    """(task, code) of every pick that failed: dropped, not placed, collision, late grasp."""
    out = []
    for k, p in enumerate(picks):
        if p["collision"]:
            out.append((k, "collision with " + ", ".join(p["collision_with"]) if p.get("collision_with")
                        else "collision"))
        if p["t_grasp"] is None or p["t_grasp"] > p["t_grasp_prescribed"] + LATE_GRASP:
            out.append((k, "late grasp"))
        if not p["grasped"]:
            out.append((k, "dropped"))
        elif not p["placed"]:
            out.append((k, "not placed"))
    return out
