"""The give-up rule of the line (issue 44): a task kept in its approach that can no longer be
served is abandoned, and the arm is sent to a safe hold from its present state.

While a task approaches, the driver (``watch.watch``) checks its committed grasp
again when the part's predicted grasp point drifts (a belt without an encoder running faster or
slower than declared: its speed learned from the track).  ``unserved`` names why the grasp can no
longer be made where it is so — the part still upstream of its reach window at the approach's end,
or past the window's end less ``Timing.slack`` at the grasp (the lift too must be done in reach) —
and the driver adds the min-tf model's verdict (``line.cycle.LineCycles.fits``: the approach and
descend from the tool's present point no longer fit before the grasp).  Where the scheduler then
finds nothing to replace it with, the task used to go on ("nothing feasible: kept"): its targets
followed the track to the edge of reach and the arm ran away (the harsh ``line_assembly`` study,
seeds 8, 9, 22, 42: a grasp planned 0.06–0.12 s before the part's deadline, the belt then seen
×1.16–1.33 faster; the joints past 3 rad/s, torque at its limits).

Abandoned instead, where ``unserved`` names a reason with the lift's start in place of the
scheduler's slack — the part upstream of its window at the approach's end, or past its end a
``dwell`` after the grasp, where the lift starts above it (the window is where a top-down grasp
and the lift above it have a posture): the task leaves the run's tasks, its part is named ``not
reachable in time`` in the decision log (so in the metrics' parts), and the arm goes to
``hold_of``'s point — a segment from the present state (as a replaced approach restarts: the
torque's jump at the switch is the metrics' ``abandoned[*].torque_jump_Nm``) to the tool's
present x, y at the lift's height above the part (``PickTaskConfig.lift_height``: the height a
held part rides at, clear of the parts on the belt under it), or where that has no top-down
posture, the tool's present point, in the tasks' default retreat tf.  Then the arm is free for
the next part.

Otherwise the task goes on as before ("nothing feasible: kept").  Measured, two stricter rules
lost parts the run without a rule placed: giving up where the model's approach did not fit (harsh
seed 9's first task, chosen at 0.5 s, found at 0.7 s to have no top-down posture along the
model's way from the moving arm: ``NoTfFits``, not a tf too short), and giving up by the
scheduler's slack (seed 5's third part, its belt seen at 0.20 m/s against 0.10 m/s declared,
placed when kept).  Choices the issue leaves open: the hold keeps the tool's yaw, and the
abandoned part is not looked at again (it was already past what the scheduler could find for it).
"""

from __future__ import annotations

from typing import Callable, Optional

import numpy as np

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.worlds.pick.line.plan import Hold
from ptint_drake.worlds.pick.line.scheduler import Track

REASON = "not reachable in time"  # the part's failure where its task is abandoned (``line.metrics``)


def unserved(track: Track, window: tuple, grasp: float, now: float, approach_end: float, slack: float) -> str:
    """Why the grasp of ``track`` at ``grasp`` can no longer be made by its reach ``window``
    ([s_in, s_out] along its belt, m) at its known speed: the part not yet in the window at the
    approach's end, or past ``s_out`` less ``slack`` s of its ride at the grasp; "" if it can."""
    s_in, s_out = window
    if track.s + track.speed * (approach_end - now) < s_in:
        return f"upstream of reach at the approach's end ({approach_end:.2f} s)"
    if track.s + track.speed * (grasp - now) > s_out - track.speed * slack:
        return f"past reach at the grasp ({grasp:.2f} s) and the lift"
    return ""


def hold_of(now: float, tool: np.ndarray, yaw: float, part: np.ndarray,
            reachable: Callable[[np.ndarray], Optional[np.ndarray]]) -> Hold:
    """The ``Hold`` from ``now`` of a task given up (module docstring): the ``tool``'s point
    (world, m) raised to ``lift_height`` above the ``part``'s centre if lower, where ``reachable``
    (point → a top-down posture or None) finds a posture, else the tool's point; ``yaw`` kept."""
    task = PickTaskConfig()
    tool = np.asarray(tool, float)
    point = np.array([tool[0], tool[1], max(tool[2], float(part[2]) + task.lift_height)])
    if reachable(point) is None:
        point = tool
    return Hold(now, task.retreat.tf, task.retreat.beta, tuple(float(c) for c in point), float(yaw))
