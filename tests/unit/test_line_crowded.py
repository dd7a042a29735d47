"""Issue 44: a committed line task whose grasp a part arriving after the decision now crowds
(``watch.crowded``) — the scheduler's finger rule asked again at every stop of the approach, at
the task's own grip yaw.  Session 53's UR5e line of 40 mm cans on a 0.05 m/s belt grasped a can
whose two followers, released after its decision, stood 5 mm behind it: its open fingers touched
both (141.7 N); now the task is decided again or given up, the part ``blocked``."""

from types import SimpleNamespace

import numpy as np

from ptint_drake.worlds.pick.line.scheduler import Timing, Track
from ptint_drake.worlds.pick.line.watch import crowded

TIMING = Timing(lead=1.7, step=0.1, horizon=10.0, slack=0.5, margin=0.012, finger=(0.006, 0.02))


def _cube(i, s):
    """A 30 mm cube on a belt along +y at x = 0.25 m, ``s`` m along it, at 0.05 m/s."""
    return Track(i, "cube", "belt", (0.25, s, 0.15), s, (0.0, 1.0, 0.0), 0.05, (1.0, 0.0, 0.0),
                 0.03, 0.0212)


def _driver(grip_yaw):
    task = SimpleNamespace(grip_yaw=grip_yaw)
    return SimpleNamespace(scenario=SimpleNamespace(pick=SimpleNamespace(tasks=[task])), timing=TIMING)


def test_a_part_arriving_behind_the_chosen_one_crowds_fingers_closing_along_the_belt():
    chosen, follower = _cube(0, 0.0), _cube(1, -0.045)  # 45 mm behind, centre to centre
    tracks = [chosen, follower]
    # fingers closing along the belt: the rear finger stands where the follower is
    assert crowded(_driver(0.5 * np.pi), 0, chosen, tracks, 12.0, 10.0) == 1
    # closing across the belt: both fingers clear of it
    assert crowded(_driver(0.0), 0, chosen, tracks, 12.0, 10.0) is None
    # the chosen part alone, or its follower far behind: nothing crowds it
    assert crowded(_driver(0.5 * np.pi), 0, chosen, [chosen], 12.0, 10.0) is None
    assert crowded(_driver(0.5 * np.pi), 0, chosen, [chosen, _cube(1, -0.2)], 12.0, 10.0) is None
