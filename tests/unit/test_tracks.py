"""The multi-part tracker on synthetic detections (issue 44): near neighbours, crossings, gaps,
births and deaths never switch an identity; classes, symmetric yaws and the binding to the
declared parts by class and arrival order."""

import math

import numpy as np
import pytest

from ptint_drake.systems.perception.tracks import (CONFIRMED, MAX_COAST, Detection, Tracker, TrackerSettings,
                                                  identity_switches)

RATE = 30.0
CUBE, CAN = 0, 1  # classes: a cube (yaw modulo 90°) and a cylinder (no yaw)
SYMMETRIES = [0.5 * math.pi, 0.0]


def run(parts, duration, *, objects=(), arrival=(), belts=((0.0, 0.1, 0.0),), view=None, noise=0.0005,
        seed=0, shuffle=True):
    """Per frame: each part's detection (when visible and not hidden) fed to a tracker; returns the
    tracker and, per frame, (part, track id) of what the tracker did with each part's detection.
    ``parts``: dicts with start (x, y), belt, kind, yaw, optional hidden (t0, t1)."""
    rng = np.random.default_rng(seed)
    tracker = Tracker(TrackerSettings(SYMMETRIES, [np.array(v) for v in belts], list(objects), list(arrival),
                                      visible=view))
    frames = []
    for k in range(int(duration * RATE) + 1):
        t = k / RATE
        dets, owners = [], []
        for i, p in enumerate(parts):
            v = np.asarray(belts[p["belt"]])
            pos = np.array([*p["start"], 0.15]) + v * t
            hidden = p.get("hidden", (np.inf, np.inf))
            if (view is not None and not view(pos)) or hidden[0] <= t < hidden[1] or t < p.get("from", 0.0):
                continue
            yaw = p.get("yaw", 0.0) + rng.normal(0.0, 0.01)
            fold = SYMMETRIES[p["kind"]]
            yaw = (yaw + 0.5 * fold) % fold - 0.5 * fold if fold else 0.0
            dets.append(Detection(pos + rng.normal(0.0, noise, 3) * [1, 1, 0.2], yaw, p["kind"], p["belt"]))
            owners.append(i)
        order = rng.permutation(len(dets)) if shuffle else np.arange(len(dets))
        dets, owners = [dets[j] for j in order], [owners[j] for j in order]
        assigned = tracker.load(tracker.state_vector()).step(t, dets)  # (the state survives a round trip)
        frames.append([(owners[j], tid) for tid, j in assigned.items()])
    return tracker, frames


def in_view(lo=-0.35, hi=0.2):
    return lambda p: lo <= p[1] <= hi


@pytest.mark.parametrize("spacing", [0.06, 0.045])
def test_near_neighbours_on_one_belt_keep_their_ids(spacing):
    parts = [{"start": (0.3, -0.2), "belt": 0, "kind": CUBE},
             {"start": (0.3, -0.2 - spacing), "belt": 0, "kind": CUBE}]
    tracker, frames = run(parts, 3.0, noise=0.001)
    ids = identity_switches(frames)
    assert ids["idsw"] == 0
    assert all(len(tracks) == 1 for tracks in ids["tracks_per_part"].values())
    assert all(len(owners) == 1 for owners in ids["parts_per_track"].values())


def test_a_part_hidden_for_a_second_keeps_its_track_and_its_neighbour_does_not_take_it():
    # the arm hides the front part for 1 s (as before its grasp); its neighbour 60 mm behind stays seen
    parts = [{"start": (0.3, -0.2), "belt": 0, "kind": CUBE, "hidden": (0.8, 1.8)},
             {"start": (0.3, -0.26), "belt": 0, "kind": CUBE}]
    tracker, frames = run(parts, 3.0, noise=0.001)
    assert identity_switches(frames)["idsw"] == 0
    assert [tr.id for tr in tracker.tracks] == [1, 2]


def test_a_gap_longer_than_the_coast_ends_the_track_and_a_picked_part_is_ended():
    parts = [{"start": (0.3, -0.2), "belt": 0, "kind": CUBE, "hidden": (0.5, 10.0)}]
    tracker, frames = run(parts, 0.5 + MAX_COAST + 0.2)
    assert tracker.tracks == [] and tracker.bound == []
    assert identity_switches(frames)["idsw"] == 0


def test_births_and_deaths_as_parts_enter_and_leave_the_view():
    parts = [{"start": (0.3, -0.30), "belt": 0, "kind": CUBE},  # in view from the start, leaves at 5 s
             {"start": (0.3, -0.50), "belt": 0, "kind": CUBE},  # enters at 1.5 s
             {"start": (0.3, -0.80), "belt": 0, "kind": CAN}]  # enters at 4.5 s
    seen = {}
    tracker = None
    for duration in (1.0, 2.0, 5.2, 7.0):
        tracker, frames = run(parts, duration, view=in_view())
        seen[duration] = sorted(tr.id for tr in tracker.tracks)
    assert seen == {1.0: [1], 2.0: [1, 2], 5.2: [2, 3], 7.0: [2, 3]}
    assert identity_switches(frames)["idsw"] == 0
    assert [tr.kind for tr in tracker.tracks] == [CUBE, CAN]


def test_crossing_paths_of_two_belts_keep_their_ids():
    # a straight belt (+y) and one at 45°: their parts pass 15 mm apart at t = 1.5 s
    belts = ((0.0, 0.1, 0.0), (0.0707, 0.0707, 0.0))
    cross = np.array([0.3, 0.0])
    parts = [{"start": tuple(cross - 1.5 * np.array(belts[0][:2]) + [0.015, 0.0]), "belt": 0, "kind": CUBE},
             {"start": tuple(cross - 1.5 * np.array(belts[1][:2])), "belt": 1, "kind": CAN}]
    tracker, frames = run(parts, 3.0, belts=belts, noise=0.001)
    ids = identity_switches(frames)
    assert ids["idsw"] == 0
    assert sorted(map(len, ids["tracks_per_part"].values())) == [1, 1]


def test_the_yaw_is_unwrapped_by_the_class_symmetry():
    # a cube turning slowly through ±45°, where its folded fit jumps by 90°: the track's yaw goes on
    tracker = Tracker(TrackerSettings(SYMMETRIES, [np.zeros(3)]))
    for k in range(60):
        yaw = math.radians(30.0 + k)  # 30° … 89°: folded, the fit jumps from +45° to −45°
        fold = (yaw + 0.25 * math.pi) % (0.5 * math.pi) - 0.25 * math.pi
        tracker.step(k / RATE, [Detection(np.array([0.3, 0.0, 0.15]), fold, CUBE, 0)])
    (track,) = tracker.tracks
    assert math.degrees(track.yaw) == pytest.approx(89.0, abs=1e-6)


def test_tasks_bind_by_class_and_arrival_order():
    # declared: a cube (object 0), a can (1), a cube (2) on one belt; arrival: cube 2 first, then the can,
    # then cube 0 — each track goes to the first declared part of its class not yet bound in that order
    parts = [{"start": (0.3, -0.10), "belt": 0, "kind": CUBE},  # arrives first
             {"start": (0.3, -0.20), "belt": 0, "kind": CAN},
             {"start": (0.3, -0.28), "belt": 0, "kind": CUBE}]
    objects = [(CUBE, 0), (CAN, 0), (CUBE, 0)]
    tracker, _ = run(parts, 1.0, objects=objects, arrival=[2, 1, 0])
    by_id = {tr.id: tr for tr in tracker.tracks}
    assert all(tr.status == CONFIRMED for tr in tracker.tracks)
    first, can, last = (min(by_id.values(), key=lambda tr, y=y: abs(tr.x[1] - y)) for y in (0.0, -0.1, -0.18))
    assert (first.object, can.object, last.object) == (2, 1, 0)
    assert tracker.bound == [last.id, can.id, first.id]


def test_a_confirmed_track_does_not_take_a_detection_of_another_class_over_its_own():
    tracker = Tracker(TrackerSettings(SYMMETRIES, [np.zeros(3)]))
    for k in range(5):
        tracker.step(k / RATE, [Detection(np.array([0.3, 0.0, 0.15]), 0.0, CUBE, 0)])
    # a can 6 mm off and the cube 9 mm off (within the gate): the cube's own class wins
    assigned = tracker.step(5 / RATE, [Detection(np.array([0.306, 0.0, 0.15]), 0.0, CAN, 0),
                                       Detection(np.array([0.3, 0.009, 0.15]), 0.0, CUBE, 0)])
    assert assigned[1] == 1


def test_identity_switches_counts_a_track_that_takes_another_part():
    frames = [[(0, 1), (1, 2)], [(0, 1), (1, 2)], [(1, 1)], [(0, 3), (1, 1)]]
    out = identity_switches(frames)
    assert out["idsw"] == 2  # part 1 to track 1, then part 0 to track 3
    assert out["parts_per_track"][1] == [0, 1]


def test_a_part_entering_beside_a_coasting_track_is_born_not_taken():
    # the front part is picked at 1 s (never seen again); the one 60 mm behind enters the view at 1.2 s
    # while the front part's track still coasts: the gate keeps it from taking the newcomer
    parts = [{"start": (0.3, -0.2), "belt": 0, "kind": CUBE, "hidden": (1.0, 10.0)},
             {"start": (0.3, -0.26), "belt": 0, "kind": CUBE, "from": 1.2}]
    tracker, frames = run(parts, 2.0, noise=0.001)
    ids = identity_switches(frames)
    assert ids["idsw"] == 0 and ids["tracks_per_part"] == {0: [1], 1: [2]}
