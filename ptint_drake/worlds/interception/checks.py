"""The interception world's checks that need no robot model (each a one-line ``ScenarioError``
naming the field): the segments in time order within the run, exactly one motion per target, a
thrown object above the floor at tf, orientation noise only where an orientation is measured."""

import math

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.fields import positive, vector3
from ptint_drake.systems.perception.belt_regions import perception_belts
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose, describe_pose, in_view
from ptint_drake.systems.task.orientation import has_orientation
from ptint_drake.systems.task.targets import WaypointTarget
from ptint_drake.worlds.interception.objects import interception_targets

TARGET_KINDS = ("sinusoid", "linear", "waypoints", "ballistic")


def check_interceptions(s) -> None:
    """Every ``interceptions[i]``: its timing, its target and, for a throw, the floor."""
    if not s.interceptions:
        raise ScenarioError("interceptions: at least one interception is needed")
    for i, ic in enumerate(s.interceptions):
        _validate_interception(s, i, ic)
        _validate_target(ic.target, f"interceptions[{i}].target")
        if ic.target.ballistic is not None:
            _validate_throw(ic, f"interceptions[{i}]")
    _validate_rotation_noise(s)
    _validate_rgbd_view(s)


def _validate_rgbd_view(s) -> None:
    """With ``measurement.sensor: rgbd``: every object rides a conveyor (a horizontal linear
    motion) and is in the camera's view at its segment's start and at its interception time
    (else nothing would be seen: rejected before the run, naming the camera's pose)."""
    m = s.measurement
    if m is None or m.sensor != "rgbd" or m.camera is None:
        return
    targets = interception_targets(s)
    try:
        perception_belts(m, targets, s.duration)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    X_WC, info = camera_pose(m.camera), camera_info(m.camera)
    for i, (ic, target) in enumerate(zip(s.interceptions, targets)):
        times = (ic.start, ic.start + ic.tf)
        points = np.array([target.evaluate(t)[0:3] for t in times])
        seen = in_view(X_WC, info, points)
        if not np.all(seen):
            when = times[int(np.argmin(seen))]
            raise ScenarioError(f"measurement.camera: interceptions[{i}]'s object is not in view at "
                                f"t = {when:g} s of the camera at {describe_pose(m.camera)} (nothing to see)")


def _validate_interception(s, i: int, ic) -> None:
    where = f"interceptions[{i}]"
    if not (0.0 < ic.beta < 1.0):
        raise ScenarioError(f"{where}.beta: must be in (0, 1), got {ic.beta}")
    positive(ic.tf, f"{where}.tf")
    if not (math.isfinite(ic.start) and ic.start >= 0.0):
        raise ScenarioError(f"{where}.start: must be >= 0, got {ic.start}")
    if i == 0 and ic.start != 0.0:
        raise ScenarioError(f"{where}.start: the first interception must start at 0, got {ic.start}")
    if i > 0:
        prev = s.interceptions[i - 1]
        if ic.start < prev.start + prev.tf:
            raise ScenarioError(
                f"{where}.start: {ic.start} s is before interceptions[{i - 1}] "
                f"intercepts at {prev.start + prev.tf} s (segments must be in time order "
                f"and may not overlap)")
    if ic.start + ic.tf > s.duration + 1e-12:
        raise ScenarioError(
            f"{where}.tf: interception time {ic.start + ic.tf} s is after the end "
            f"of the simulation (duration {s.duration} s)")


def _validate_target(t, where: str) -> None:
    kinds = [k for k in TARGET_KINDS if getattr(t, k) is not None]
    if len(kinds) != 1:
        raise ScenarioError(
            f"{where}: exactly one of {', '.join(TARGET_KINDS)} is needed, got "
            f"{', '.join(kinds) if kinds else 'none'}")
    if t.sinusoid is not None:
        for name in ("center", "amplitude", "phase"):
            vector3(getattr(t.sinusoid, name), f"{where}.sinusoid.{name}")
        if not math.isfinite(t.sinusoid.omega):
            raise ScenarioError(f"{where}.sinusoid.omega: must be finite")
    elif t.waypoints is not None:
        try:
            WaypointTarget(t.waypoints.time, t.waypoints.position)
        except ValueError as exc:
            raise ScenarioError(f"{where}.waypoints.{exc}") from None
    elif t.ballistic is not None:
        for name in ("start", "velocity", "gravity"):
            vector3(getattr(t.ballistic, name), f"{where}.ballistic.{name}")
        if not (math.isfinite(t.ballistic.release) and t.ballistic.release >= 0.0):
            raise ScenarioError(f"{where}.ballistic.release: must be >= 0, got {t.ballistic.release}")
    else:
        vector3(t.linear.start, f"{where}.linear.start")
        vector3(t.linear.velocity, f"{where}.linear.velocity")
    _validate_orientation(t, where)


def _validate_orientation(t, where: str) -> None:
    """``orientation`` (rpy_deg, rate_deg_s: 3 finite numbers each) and waypoints' ``rpy_deg``
    (one [r, p, y] per sample time); not both."""
    if t.orientation is not None:
        vector3(t.orientation.rpy_deg, f"{where}.orientation.rpy_deg")
        vector3(t.orientation.rate_deg_s, f"{where}.orientation.rate_deg_s")
    rpy = t.waypoints.rpy_deg if t.waypoints is not None else []
    if not rpy:
        return
    if t.orientation is not None:
        raise ScenarioError(f"{where}.waypoints.rpy_deg: orientation or rpy_deg, not both")
    if len(rpy) != len(t.waypoints.time):
        raise ScenarioError(f"{where}.waypoints.rpy_deg: one [r, p, y] per time is needed, got {len(rpy)} "
                            f"for {len(t.waypoints.time)} times")
    for k, sample in enumerate(rpy):
        vector3(sample, f"{where}.waypoints.rpy_deg[{k}]")


def _validate_throw(ic, where: str) -> None:
    """A thrown object: the segment starts at or after the release, and the object is above the
    floor (z ≥ 0) at the interception time (the reach is checked with the robot model)."""
    b = ic.target.ballistic
    if ic.start < b.release:
        raise ScenarioError(f"{where}.start: {ic.start} s is before the object is thrown "
                            f"(target.ballistic.release {b.release} s)")
    tau = ic.tf + ic.start - b.release
    z = b.start[2] + b.velocity[2] * tau + 0.5 * b.gravity[2] * tau * tau
    if z < 0.0:
        raise ScenarioError(f"{where}.tf: the thrown object is below the floor at tf "
                            f"(z = {z:.3f} m at t = {ic.start + ic.tf:g} s)")


def _validate_rotation_noise(s) -> None:
    """``measurement.rot_noise_deg`` only where the camera measures an orientation: some target
    has one (``orientation`` or waypoints' ``rpy_deg``)."""
    if s.measurement is None or s.measurement.rot_noise_deg is None:
        return
    if not any(has_orientation(target) for target in interception_targets(s)):
        raise ScenarioError("measurement.rot_noise_deg: no target has an orientation, so the camera measures "
                            "none (give a target an orientation, or remove rot_noise_deg)")
