"""Issue 44's outgoing belt (``worlds.pick.out_belt``): the free place point keeps the pitch from
every part already put on the belt and is the nearest such point to the preferred one; what counts
as put on the belt; a task's place riding the belt (``tasks.place_target``, ``place_ride``)."""

import numpy as np
from pydrake.math import RotationMatrix

from ptint_drake.config.pick import BeltConfig, PartConfig, PickConfig, PickTaskConfig
from ptint_drake.worlds.pick.out_belt import PLACE_GAP, free_point, on_belt, pitch
from ptint_drake.worlds.pick.tasks import pick_plan, place_ride, place_target

CUBE = PartConfig(name="cube", shape="box", size=[0.03, 0.03, 0.03])
FINGER = 0.02  # m, the open fingers' width along the belt


def test_the_pitch_keeps_the_gap_between_the_part_or_the_fingers_and_the_part_before():
    assert np.isclose(pitch(CUBE, CUBE, FINGER), 0.03 + PLACE_GAP)
    wide = 0.05  # fingers wider than the cube: they, not the cube, come nearest the part before
    assert np.isclose(pitch(CUBE, CUBE, wide), 0.5 * wide + 0.015 + PLACE_GAP)


def test_the_free_point_is_the_nearest_to_the_preferred_that_keeps_every_pitch():
    gap = pitch(CUBE, CUBE, FINGER)
    assert free_point(0.0, -0.3, 0.3, CUBE, [], FINGER) == 0.0
    # a part 10 mm downstream of the preferred point: the point one pitch upstream of it
    assert np.isclose(free_point(0.0, -0.3, 0.3, CUBE, [(0.01, CUBE)], FINGER), 0.01 - gap)
    rng = np.random.default_rng(3)
    grid = np.linspace(-0.3, 0.3, 6001)
    for _ in range(300):
        placed = [(float(a), CUBE) for a in rng.uniform(-0.3, 0.3, rng.integers(0, 8))]
        preferred, lo, hi = float(rng.uniform(-0.3, 0.3)), -0.3, float(rng.uniform(-0.2, 0.3))
        found = free_point(preferred, lo, hi, CUBE, placed, FINGER)
        ok = [s for s in grid if lo <= s <= hi and all(abs(s - a) >= gap for a, _ in placed)]
        if found is None:
            assert not ok
            continue
        assert lo - 1e-9 <= found <= hi + 1e-9
        assert all(abs(found - a) >= gap - 1e-9 for a, _ in placed)
        assert abs(found - preferred) <= min(abs(s - preferred) for s in ok) + 1e-9


def test_a_part_counts_as_put_on_the_belt_when_it_rests_upright_inside_its_width():
    belt = BeltConfig(name="out", center=[0.21, 0.0, 0.135], width=0.08, length=1.6)
    level = np.eye(3)
    assert on_belt(belt, [0.21, 0.3, 0.15], level, CUBE)
    assert not on_belt(belt, [0.21, 0.3, 0.16], level, CUBE)  # 10 mm above: not resting
    assert not on_belt(belt, [0.21 + 0.025, 0.3, 0.15], level, CUBE)  # its corner past the edge
    assert not on_belt(belt, [0.21, 0.9, 0.15], level, CUBE)  # past the belt's end
    assert not on_belt(belt, [0.21, 0.3, 0.15], RotationMatrix.MakeXRotation(0.35).matrix(), CUBE)


def test_a_task_on_a_belt_places_the_part_across_it_riding_at_its_speed():
    belts = [BeltConfig(name="in", center=[0.30, 0.0, 0.135]),
             BeltConfig(name="out", center=[0.21, 0.0, 0.135], direction=[0.0, -1.0, 0.0], speed=0.15)]
    part = PartConfig(name="cube_0", belt="in", yaw_deg=30.0)
    task = PickTaskConfig(part="cube_0", belt="out", belt_at=0.1)
    pick = PickConfig(belts=belts, parts=[part], tasks=[task])
    kind, index, yaw = place_target(pick, task)
    assert (kind, index) == ("belt", 1)
    # across the belt (its direction −y: yaw 0 or 180°), the branch nearest the part's 30°
    assert np.isclose(yaw, 0.0)
    assert np.allclose(place_ride(pick, task), [0.0, -0.15, 0.0])
    plan = pick_plan(pick)
    riding = [s for s in plan.segments if s.phase in ("carry", "place", "retreat")]
    assert all(s.kind == "belt" and np.allclose(s.ride, [0.0, -0.15, 0.0]) and s.along == 0.1 for s in riding)
    assert all(np.allclose(s.ride, 0.0) for s in plan.segments if s.phase in ("approach", "descend", "lift"))
