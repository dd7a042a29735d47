"""Before a grasp seen by the camera (issue 44): may task k's part be grasped?  Read at its last
attempt's descend start (``world.PickRun``), from the controller side's view only (the
perception's tracks and estimates, never the truth).

- ``part not seen``: its part was never seen, or fitted fewer than ``camera.MIN_FITS`` times (too
  few for a velocity to aim at);
- ``blocked``: the open fingers would not fit between it and a neighbour.  At the prescribed grasp
  time, in the part's horizontal frame (its estimated x axis: the axis the fingers close along,
  ``targets``' top-down grasp), each finger is a rectangle from half the opening (the part's
  width + the task's ``margin``) outward by the finger's thickness, as wide as the finger
  (``finger_extent``: the finger's collision boxes); each other live track, predicted to then on
  its filter, is a disc of its class's reach (half the top face's diagonal: any yaw).  A finger
  closer than ``FINGER_MARGIN`` to a disc blocks the grasp.

``grasp_refusal`` returns (the task's refusal, its check's record) or None.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.geometry import Box

from ptint_drake.systems.perception.part_fit import reach

FINGER_MARGIN = 0.003  # m, the estimates' error allowance between a finger and a neighbour
# m, (thickness, width) of a finger when its collision geometry has no box (the RV-M1 hand's)
DEFAULT_FINGER = (0.006, 0.02)


def finger_extent(station) -> tuple[float, float]:
    """(thickness outward of the pad's inner face, width across) of the left finger's collision
    boxes (the finger link's x = 0 plane is the pad's inner face: models/rvm1_gripper.sdf)."""
    plant, inspector = station.plant, station.scene_graph.model_inspector()
    body = plant.GetBodyByName("left_finger", station.gripper)
    lo_x, hi_y = 0.0, 0.0
    for gid in plant.GetCollisionGeometriesForBody(body):
        shape = inspector.GetShape(gid)
        if not isinstance(shape, Box):
            continue
        X = inspector.GetPoseInFrame(gid)
        half = 0.5 * np.array([shape.width(), shape.depth(), shape.height()])
        signs = np.array(np.meshgrid([-1, 1], [-1, 1], [-1, 1])).T.reshape(-1, 3)
        corners = np.array([X.multiply(half * s) for s in signs])
        lo_x, hi_y = min(lo_x, corners[:, 0].min()), max(hi_y, np.abs(corners[:, 1]).max())
    return (-lo_x, 2.0 * hi_y) if lo_x < 0.0 else DEFAULT_FINGER


def finger_clearance(centre, axis, opening: float, finger: tuple, neighbour, radius: float) -> float:
    """m: the gap between the nearer finger (module docstring) and a neighbour's disc."""
    a = np.array([axis[0], axis[1]]) / max(math.hypot(axis[0], axis[1]), 1e-12)
    b = np.array([-a[1], a[0]])
    d = np.asarray(neighbour, float)[0:2] - np.asarray(centre, float)[0:2]
    s_a, s_b = abs(float(d @ a)), abs(float(d @ b))
    inner, outer = 0.5 * opening, 0.5 * opening + finger[0]
    gap = math.hypot(max(inner - s_a, 0.0, s_a - outer), max(s_b - 0.5 * finger[1], 0.0))
    return gap - radius


def grasp_refusal(built, context, task: int, part: int, t: float, min_fits: int, margin: float):
    """(refusal, check record) of task ``task`` (part ``part``; ``margin``: its open fingers'
    clearance around the part) at its descend start ``t``, or None (module docstring).  A track
    whose centre is within the part's own reach is the part itself (a track born anew)."""
    from ptint_drake.worlds.pick.part_tracks import catalog  # noqa: PLC0415

    parts, estimator = built.estimates.parts, built.estimates.estimator
    ec = estimator.GetMyContextFromRoot(context)
    fits = int(estimator.GetOutputPort("fit_counts").Eval(ec)[part])
    seen = parts.GetOutputPort("seen").Eval(parts.GetMyContextFromRoot(context))[part] > 0.5
    if not seen or fits < min_fits:
        return "part not seen", {"state": "not seen", "t": t, "fits": fits}
    tracker = estimator.tracker(ec)
    own = tracker.of_object(part)
    pc = parts.GetMyContextFromRoot(context)
    pose = parts.GetOutputPort(f"part_{part}_pose").Eval(pc)
    R = parts.GetOutputPort(f"part_{part}_rotation").Eval(pc)[0:9].reshape(3, 3)
    grasp = built.plan.grasp_times[task]
    centre = pose[0:3] + pose[3:6] * (grasp - t)
    config = built.station.config.parts[part]
    opening = float(config.size[0]) + margin
    finger = finger_extent(built.station)
    kinds = catalog(built.station.config)[0]
    for track in tracker.tracks:
        where = track.x[0:2] + track.x[2:4] * (grasp - track.t)
        if (own is not None and track.id == own.id) or np.hypot(*(where - centre[0:2])) < reach(config.shape,
                                                                                                config.size):
            continue
        gap = finger_clearance(centre, R[:, 0], opening, finger, where, reach(*kinds[track.kind]))
        if gap < FINGER_MARGIN:
            return "blocked", {"state": "blocked", "t": t, "track": track.id, "clearance_mm": 1e3 * gap}
    return None

