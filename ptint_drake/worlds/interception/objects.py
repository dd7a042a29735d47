"""The interception world's objects: the analytic motion of each ``interceptions[i].target``
and the schedule of the segments (SPEC 2.1) that intercept them."""

from __future__ import annotations

from ptint_drake.config.schema import Scenario, TargetConfig
from ptint_drake.systems.task.orientation import OrientedTarget, SlerpOrientation, SpinningOrientation
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import BallisticTarget, LinearTarget, SinusoidTarget, WaypointTarget


def interception_schedule(scenario: Scenario) -> Schedule:
    """The segments of ``interceptions``: start, tf and β of each."""
    return Schedule([Segment(i.start, i.tf, i.beta) for i in scenario.interceptions])


def interception_targets(scenario: Scenario) -> list:
    """The target object of every interception (``make_target``)."""
    return [make_target(i.target) for i in scenario.interceptions]


def make_target(config: TargetConfig):
    """The target object of a ``target`` block: its position kind, with its orientation
    (``orientation.OrientedTarget``) when it has one (``orientation`` or waypoints' ``rpy_deg``)."""
    if config.sinusoid is not None:
        s = config.sinusoid
        target = SinusoidTarget(s.center, s.amplitude, s.omega, s.phase)
    elif config.waypoints is not None:
        target = WaypointTarget(config.waypoints.time, config.waypoints.position)
    elif config.ballistic is not None:
        b = config.ballistic
        target = BallisticTarget(b.start, b.velocity, b.gravity, b.release)
    else:
        target = LinearTarget(config.linear.start, config.linear.velocity)
    if config.orientation is not None:
        o = config.orientation
        return OrientedTarget(target, SpinningOrientation(o.rpy_deg, o.rate_deg_s))
    if config.waypoints is not None and config.waypoints.rpy_deg:
        return OrientedTarget(target, SlerpOrientation(config.waypoints.time, config.waypoints.rpy_deg))
    return target
