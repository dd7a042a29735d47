"""Issue 44: the line's online scheduler (``worlds.pick.line.scheduler``) on synthetic tracks —
earliest deadline first, every skipped track named with its reason, a decision anew when the
predicted grasp point drifts."""

import numpy as np

from ptint_drake.worlds.pick.line.scheduler import Timing, Track, decide, drifted, grasp_time

TIMING = Timing(lead=1.7, step=0.1, horizon=10.0, slack=0.5, margin=0.012, finger=(0.006, 0.02))
WINDOW = (-0.3, 0.3)  # m along the belt


def track(i, s, lateral=0.0, speed=0.1, kind="cube", yaw=0.0):
    """A 30 mm cube on a belt along +y at x = 0.25 m, ``s`` m along it."""
    return Track(i, kind, "belt", (0.25 + lateral, s, 0.15), s, (0.0, 1.0, 0.0), speed,
                 (np.cos(yaw), np.sin(yaw), 0.0), 0.03, 0.0212)


def test_earliest_deadline_first_and_every_other_candidate_named():
    early, late = track(0, 0.0), track(1, -0.2)  # the downstream part leaves reach first
    d = decide(10.0, [late, early], {0: WINDOW, 1: WINDOW}, set(), {"cube": [3, 4]}, TIMING)
    assert d.track == 0 and d.slot == 3
    assert abs(d.grasp - 11.7) < 1e-9  # now + lead: already in reach
    assert abs(d.deadline - (10.0 + 0.3 / 0.1 - 0.5)) < 1e-9
    assert d.skipped == [(1, "later deadline")] and d.rivals[1] > d.deadline
    rival = {"track": 1, "reason": "later deadline", "deadline": round(d.rivals[1], 4)}
    assert d.record()["skipped"] == [rival]
    assert np.allclose(d.point, [0.25, 0.17, 0.15])


def test_a_part_leaving_reach_before_the_arm_can_be_there_is_skipped_with_its_reason():
    gone = track(0, 0.2)  # 1 s left in reach, the arm needs 1.7 s
    waiting = track(1, -0.5)  # upstream: enters at s = -0.3 in 2 s
    d = decide(0.0, [gone, waiting], {0: WINDOW, 1: WINDOW}, set(), {"cube": [0]}, TIMING)
    assert d.track == 1 and dict(d.skipped)[0] == "not reachable in time"
    # the grasp lead after the entry: in reach from the approach's start on
    assert abs(d.grasp - (2.0 + TIMING.lead)) < 1e-9


def test_a_part_far_upstream_is_not_in_reach_yet_and_an_assigned_one_is_not_looked_at():
    far = track(0, -2.0)  # 17 s away from its window
    d = decide(0.0, [far, track(1, 0.0)], {0: WINDOW, 1: WINDOW}, {1}, {"cube": [0]}, TIMING)
    assert d.track is None and d.skipped == [(0, "not in reach yet")]


def test_a_part_whose_neighbour_blocks_the_open_fingers_is_skipped():
    # fingers close along x: a neighbour 30 mm beside it across the belt is where a finger goes
    part, beside = track(0, 0.0, lateral=0.0), track(1, 0.0, lateral=0.03)
    d = decide(0.0, [part, beside], {0: WINDOW, 1: WINDOW}, set(), {"cube": [0]}, TIMING)
    assert d.track is None
    assert dict(d.skipped) == {0: "blocked (track 1)", 1: "blocked (track 0)"}
    # turned 90°: the fingers close along the belt, the neighbour beside is clear of them
    turned = track(0, 0.0, yaw=np.pi / 2)
    d = decide(0.0, [turned, beside], {0: WINDOW, 1: WINDOW}, set(), {"cube": [0]}, TIMING)
    assert d.track == 0


def test_tray_full_for_its_kind():
    d = decide(0.0, [track(0, 0.0, kind="disc")], {0: WINDOW}, set(), {"cube": [0], "disc": []}, TIMING)
    assert d.track is None and d.skipped == [(0, "tray full")]


def test_decide_again_when_the_estimate_moves():
    d = decide(0.0, [track(0, -0.1)], {0: WINDOW}, set(), {"cube": [0]}, TIMING)
    # 0.5 s later the part is where the known speed puts it: no drift
    assert drifted(track(0, -0.05), d.grasp, d.point, 0.5, 0.01) == 0.0
    # the belt runs 50 % faster than known: 25 mm ahead, the prediction 25 mm off
    moved = track(0, -0.025)
    off = drifted(moved, d.grasp, d.point, 0.5, 0.01)
    assert abs(off - 0.025) < 1e-9
    again = decide(0.5, [moved], {0: WINDOW}, set(), {"cube": [0]}, TIMING)
    # the new decision aims where the part is predicted now, and its window closes earlier
    assert np.allclose(again.point, moved.at(again.grasp, 0.5)) and again.deadline < d.deadline - 0.2


def test_grasp_time_on_a_stopped_belt():
    assert grasp_time(track(0, 0.0, speed=0.0), WINDOW, 1.0, TIMING)[0] == 1.0 + TIMING.lead
    assert grasp_time(track(0, -1.0, speed=0.0), WINDOW, 1.0, TIMING) == (None, "not in reach (belt stopped)")


def test_each_track_lead_comes_from_the_leads_model_and_a_lead_that_fits_nothing_is_named():
    """With ``leads`` (the min-tf model's approach + descend per track) the grasp time is that lead
    from now, not ``Timing.lead``; a str from the model skips the track with it."""
    near, far = track(0, 0.0), track(1, -0.1)
    asked = []

    def leads(tr, window):
        asked.append(tr.id)
        return 0.83 if tr.id == 0 else 2.4

    d = decide(10.0, [near, far], {0: WINDOW, 1: WINDOW}, set(), {"cube": [0]}, TIMING, leads)
    assert d.track == 0 and abs(d.grasp - 10.9) < 1e-9  # 0.83 s rounded up to the 0.1 s grid
    assert asked == [0]  # the later deadline is not asked for once a feasible part is found
    d = decide(10.0, [near, far], {0: WINDOW, 1: WINDOW}, set(), {"cube": [0]}, TIMING,
               lambda tr, w: "no tf fits: x" if tr.id == 0 else 2.4)
    assert d.track == 1 and dict(d.skipped)[0] == "no tf fits: x" and abs(d.grasp - 12.4) < 1e-9
    # a lead longer than the window leaves: not reachable in time (2.5 s left before the slack)
    d = decide(10.0, [near], {0: WINDOW}, set(), {"cube": [0]}, TIMING, lambda tr, w: 2.6)
    assert d.track is None and d.skipped == [(0, "not reachable in time")]
