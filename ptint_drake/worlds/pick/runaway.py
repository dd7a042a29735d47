"""During a pick run: did the arm run away?  Measured per task from the run's series.

A runaway — the controller commanding torques far beyond what the drives give, the joints far
beyond their speed limits — ends in its consequences (a collision, a part knocked off its belt,
``missed after retry``); the verdict names the runaway itself too.  Per task, over its window
(``collisions.task_window``: from its first approach to the next task's), two measured tests:

- ``saturated``: the commanded torque of some joint beyond its effort limit for at least
  ``SATURATED_FRACTION`` (50 %) of the window's time (``saturated_fraction`` of the task);
- ``joint speed beyond limit``: some joint faster than ``SPEED_RUNAWAY`` (3) times its model's
  velocity limit for ``SPEED_RUNAWAY_S`` (0.3 s) or more of the window in all
  (``joint_speed_over_s``); beside it ``joint_speed_ratio``, the largest |q̇ⱼ| / limitⱼ, and
  ``joint_speed_joint`` its joint (1-based).  A time, not a peak: by its singularity the 6-joint
  wrist flips for a moment (below) and places its part.

Thresholds, measured (rvm1_5dof, docs/pick_place.md): runs that place every part saturate at
most 12.8 % of a task's window (the four bundled picks 0.2-11.8 %, ``tests/two_belt_pick.yaml``'s
pick 0 12.8 %) and reach up to 2.24 times the model's speed limits on rvm1_5dof
(assembly_pick_place_rgbd; their planned profiles ask for as much: the feasibility warnings
before the run), 3.32 times on rvm1_6dof (``tests/two_belt_pick.yaml``: the wrist's roll at 13.3
rad/s by its singularity, under the damped pseudoinverse; places both parts) — beyond 3 times for
22 ms, and ``tests/two_belt_pick_mirrored.yaml`` on rvm1_6dof 5.18 times (its forearm roll at
20.7 rad/s), beyond 3 times for 156 ms, placing both parts.  The runaways: 1.72 s and 0.59 s
beyond 3 times (peaks 12.5 and 12.4 times).
``tests/two_belt_pick.yaml`` with pick 1's approach cut to 0.3 s runs away: 99.5 % of pick 1's
window saturated, joint 3 at 37.5 rad/s against its 3 rad/s limit (12.5 times).
A joint beyond its limit for less is warned about after the run (``run_warnings
.joint_limit_warnings``), not a verdict.
"""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.pick.collisions import task_window

SATURATED_FRACTION = 0.5  # of a task's window with a commanded torque beyond its limit
SPEED_RUNAWAY = 3.0  # times a joint's velocity limit
SPEED_RUNAWAY_S = 0.3  # s beyond it, in a task's window


def runaway_metrics(built, metrics: dict, series: dict) -> None:
    """Add to each of ``metrics["picks"]`` its window's ``saturated_fraction``, ``joint_speed_ratio``,
    ``joint_speed_joint`` and ``joint_speed_over_s`` (module docstring), from ``series``
    (``run.pick_series``: t, v, tau)."""
    t, v, tau = series["t"], series["v"], series["tau"]
    limits = np.asarray(built.arm.GetVelocityUpperLimits(), float)
    over = np.any(np.abs(tau) > built.limits * (1.0 + 1e-9), axis=1)
    dt = np.diff(t, append=t[-1]) if len(t) else np.zeros(0)
    for k, pick in enumerate(metrics["picks"]):
        start, end = task_window(built.plan, k)
        inside = (t >= start) & (t < end)
        span = float(np.sum(dt[inside]))
        pick["saturated_fraction"] = float(np.sum(dt[inside & over]) / span) if span > 0 else 0.0
        ratio = np.abs(v[inside]) / np.where(limits > 0, limits, np.inf)
        peak = np.max(ratio, axis=0) if np.any(inside) else np.zeros(1)
        pick["joint_speed_ratio"] = float(np.max(peak))
        pick["joint_speed_joint"] = int(np.argmax(peak)) + 1
        fast = np.zeros(len(t), dtype=bool)
        fast[inside] = np.any(ratio > SPEED_RUNAWAY, axis=1)
        pick["joint_speed_over_s"] = float(np.sum(dt[fast]))


def runaway_reasons(pick: dict) -> list[str]:
    """The runaway codes of one pick's metrics: ``saturated``, ``joint speed beyond limit``."""
    out = []
    if pick.get("saturated_fraction", 0.0) >= SATURATED_FRACTION:
        out.append("saturated")
    if pick.get("joint_speed_over_s", 0.0) >= SPEED_RUNAWAY_S:
        out.append("joint speed beyond limit")
    return out
