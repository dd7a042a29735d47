"""A line's plan: an idle segment, then the tasks the run decided (``route.routed_plan``).

A line starts with no task, and Drake's schedule needs a segment (``Schedule``).  The line's plan
begins with one ``IDLE_TF`` segment (phase ``idle``, task -1, a fixed point: kind ``via_slot``)
aiming at the tool's start position and yaw, so the arm holds where it stands until the first
task; every later task is an ordinary pick task (``tasks.pick_plan``) after it.  The scheduler
decides nothing before the idle segment's end.

A task the driver gives up in its approach (``driver``: it can no longer be served) leaves the
tasks; in its place the plan holds a ``Hold``: a segment like the idle one (phase ``idle``, task
-1, a fixed point) from the moment it was given up — the arm's present state, as a replaced
approach restarts — to the hold's point.  The run passes the holds after the tasks' ``Replan``
entries (``line_plan``'s ``replans``), and the segments are merged in time order.

A task kept after a drift (``watch``) is planned again at the new belief, its approach excepted:
a ``Pin`` (passed with the holds) keeps the approach's via — or its having none — as the run
follows it, whatever the routing (``route.routed_vias``) finds at the new belief, so that a
rebuild in the approach does not move the target it is under way to, and its grasp time stays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ptint_drake.systems.task.orientation import tool_yaw
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.worlds.pick.route import routed_plan, routed_vias
from ptint_drake.worlds.pick.tasks import VIA_SLOT, PickPlan, PlanSegment, Replan, Via, pick_plan
from ptint_drake.worlds.pick.ways import nominal

IDLE_TF = 0.5  # s
IDLE_BETA = 0.75


def home_pose(scenario, arm) -> tuple:
    """(position, yaw) of the end-effector frame at the scenario's start posture."""
    context = arm.CreateDefaultContext()
    arm.SetPositions(context, np.radians(scenario.robot.initial_q_deg))
    X = arm.GetFrameByName(scenario.robot.end_effector).CalcPoseInWorld(context)
    return tuple(float(c) for c in X.translation()), float(tool_yaw(X.rotation().matrix()))


@dataclass(frozen=True)
class Hold:
    """Where the tool goes when a task is given up (module docstring): from ``start`` (s) to the
    fixed ``position`` (world, m) turned to ``yaw`` (rad) in ``tf`` s, the TBG's ``beta``."""

    start: float
    tf: float
    beta: float
    position: tuple
    yaw: float

    @property
    def end(self) -> float:
        return self.start + self.tf

    def segment(self) -> tuple:
        """(``Segment``, ``PlanSegment``) of the plan: a fixed point, as the idle segment."""
        return (Segment(self.start, self.tf, self.beta),
                PlanSegment(-1, "idle", VIA_SLOT, -1, tuple(self.position), self.yaw))


@dataclass(frozen=True)
class Pin:
    """Task ``task``'s first approach as the run follows it (module docstring): its ``via`` (a
    ``tasks.Via``; None: the approach has none) kept in every later plan."""

    task: int
    via: Optional[Via]


def pin_of(plan: PickPlan, k: int) -> Pin:
    """The ``Pin`` of task k's first approach in ``plan``: its via's point and share, if any."""
    i = plan.segment_index(k, "approach", 0)
    before = plan.segments[i - 1]
    if before.task != k or before.phase != "via":
        return Pin(k, None)
    leg, rest = plan.schedule.segments[i - 1], plan.schedule.segments[i]
    return Pin(k, Via(k, "approach", tuple(before.offset), leg.tf / (leg.tf + rest.tf)))


def unpinned(replans, k: int) -> list:
    """``replans`` without task k's ``Pin`` (a task replaced or given up)."""
    return [r for r in replans if not (isinstance(r, Pin) and r.task == k)]


_LAST: dict = {}  # the last plan made, by what it was made from (``line_plan``)


def line_plan(scenario, replans: tuple = (), arm=None) -> PickPlan:
    """The idle segment, then the plan of ``scenario.pick.tasks`` (module docstring).  The last
    plan is kept by the robot, the pick block and the replans it was made from (``repr``: the driver
    makes the plan of a task it fits, then the run's rebuild asks for the same)."""
    key = repr((scenario.robot, scenario.pick, replans))
    if key not in _LAST:
        _LAST.clear()
        _LAST[key] = _line_plan(scenario, replans, arm)
    return _LAST[key]


def _line_plan(scenario, replans: tuple, arm) -> PickPlan:
    """``line_plan``, made: the tasks' plan with their ``Replan`` entries, the holds merged in."""
    holds = [r.segment() for r in replans if isinstance(r, Hold)]
    pins = {r.task: r.via for r in replans if isinstance(r, Pin)}
    replans = tuple(r for r in replans if isinstance(r, Replan))
    if arm is None:
        from ptint_drake.robot.plant import nominal_plant  # noqa: PLC0415

        arm = nominal_plant(scenario)
    home, yaw = home_pose(scenario, arm)
    idle = (Segment(0.0, IDLE_TF, IDLE_BETA), PlanSegment(-1, "idle", VIA_SLOT, -1, home, yaw))
    end = max([IDLE_TF, *(h[0].end for h in holds)])
    if not scenario.pick.tasks:
        merged = sorted([idle, *holds], key=lambda pair: pair[0].start)
        return PickPlan(Schedule([m[0] for m in merged]), tuple(m[1] for m in merged),
                        ((0.0, scenario.pick.gripper.initial_opening),), (), (), end)
    plan = routed_plan(scenario, replans, arm) if not pins else _pinned_plan(scenario, replans, arm, pins)
    pairs = [idle, *zip(plan.schedule.segments, plan.segments), *holds]
    merged = sorted(pairs, key=lambda pair: pair[0].start)
    return PickPlan(Schedule([m[0] for m in merged]), tuple(m[1] for m in merged), plan.commands,
                    plan.close_times, plan.grasp_times, max(plan.end, end), plan.widths, plan.attempts)


def _pinned_plan(scenario, replans: tuple, arm, pins: dict) -> PickPlan:
    """``route.routed_plan`` with the first approach of each pinned task as its ``Pin`` keeps it."""
    vias = routed_vias(scenario, nominal(scenario, arm), replans)
    vias = tuple(v for v in vias if not (v.phase == "approach" and v.task in pins))
    return pick_plan(scenario.pick, replans, vias + tuple(v for v in pins.values() if v is not None))
