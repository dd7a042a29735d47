"""Checks of a scenario that need no robot model (the model-dependent ones — reachability,
effort limits — live in ``robot``); each failure is a ``ScenarioError`` whose one-line
message names the field."""

import math

from pydrake.systems.analysis import GetIntegrationSchemes

from ptint_drake.controllers import CONTROLLERS, REGISTRY, known_type, plugin
from ptint_drake.metrics import validate_criteria
from ptint_drake.systems.camera import validate_measurement
from ptint_drake.systems.orientation import has_orientation
from ptint_drake.systems.sliding_surface import SIGMA_POLICIES, SWITCHING_LAWS
from ptint_drake.systems.targets import WaypointTarget
from ptint_drake.systems.task import TASKS

IMPLEMENTATIONS = ("fused", "blocks")
TARGET_KINDS = ("sinusoid", "linear", "waypoints", "ballistic")


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message names the field."""


def _vector3(value, where: str):
    if len(value) != 3:
        raise ScenarioError(f"{where}: must have 3 entries, got {len(value)}")
    if not all(math.isfinite(v) for v in value):
        raise ScenarioError(f"{where}: must be finite, got {list(value)}")


def _nonnegative(value: float, where: str):
    if not (math.isfinite(value) and value >= 0.0):
        raise ScenarioError(f"{where}: must be >= 0, got {value}")


def _positive(value: float, where: str):
    if not (math.isfinite(value) and value > 0.0):
        raise ScenarioError(f"{where}: must be > 0, got {value}")


def validate(s) -> None:
    """Checks that need no robot model (the model-dependent ones live in ``robot``)."""
    _positive(s.duration, "duration")
    _validate_controller(s.controller)
    for check, config in ((validate_criteria, s.criteria), (validate_measurement, s.measurement)):
        if config is None:
            continue
        try:
            check(config)
        except ValueError as exc:
            raise ScenarioError(str(exc)) from None
    _validate_plant(s.plant)
    _validate_multibody(s.multibody, s.controller.control_period)
    for name in ("max_error", "max_joint_speed"):
        _positive(getattr(s.limits, name), f"limits.{name}")
    _nonnegative(s.limits.singular_value_warning, "limits.singular_value_warning")
    _validate_simulator(s.simulator)
    if s.pick is not None:
        _validate_pick(s)
        return
    if not s.interceptions:
        raise ScenarioError("interceptions: at least one interception is needed")
    for i, ic in enumerate(s.interceptions):
        _validate_interception(s, i, ic)
        _validate_target(ic.target, f"interceptions[{i}].target")
        if ic.target.ballistic is not None:
            _validate_throw(ic, f"interceptions[{i}]")
    _validate_rotation_noise(s)


def _validate_controller(c) -> None:
    for name in ("K", "Lambda", "k", "k_hold", "epsilon", "delta"):
        _positive(getattr(c, name), f"controller.{name}")
    for name in ("alpha_hold", "pinv_damping", "null_space_damping", "null_space_rate"):
        _nonnegative(getattr(c, name), f"controller.{name}")
    if not known_type(c.type):
        raise ScenarioError(f"controller.type: must be one of {', '.join(CONTROLLERS)}, or {plugin.FORM}, "
                            f"got {c.type!r}")
    for name, value, allowed in (("switching", c.switching, SWITCHING_LAWS),
                                 ("implementation", c.implementation, IMPLEMENTATIONS),
                                 ("sigma_policy", c.sigma_policy, SIGMA_POLICIES)):
        if value not in allowed:
            raise ScenarioError(f"controller.{name}: must be one of {', '.join(allowed)}, got {value!r}")
    if c.switching != "sign":
        _positive(c.phi, "controller.phi")
    if c.task not in TASKS:
        raise ScenarioError(f"controller.task: must be one of {', '.join(TASKS)}, got {c.task!r}")
    if c.task != "position" and c.type != "ptsmc" and not plugin.is_plugin(c.type):
        raise ScenarioError(f"controller.task: {c.task!r} is implemented by ptsmc (and a plugin gets it in "
                            f"params['task']), not {c.type!r}")
    _positive(c.rot_scale, "controller.rot_scale")
    if not (math.isfinite(c.control_period) and c.control_period >= 0.0):
        raise ScenarioError(f"controller.control_period: must be > 0 s (or 0 for continuous control), "
                            f"got {c.control_period}")
    for entry in REGISTRY.values():  # each controller's own block: messages name it from "<name>." on
        if entry.config is not None and hasattr(entry.config, "validate"):
            try:
                getattr(c, entry.name).validate()
            except ValueError as exc:
                raise ScenarioError(f"controller.{exc}") from None
    _validate_params(c)


def _validate_params(c) -> None:
    """``controller.params``: a plugin's settings (numbers, lists of numbers, strings)."""
    if c.params and c.type in REGISTRY:
        raise ScenarioError(f"controller.params: only a plugin controller ({plugin.FORM}) takes params; "
                            f"{c.type!r} has its own settings")
    if c.task != "position" and c.params.get("task", c.task) != c.task:
        raise ScenarioError(f"controller.params.task: a plugin gets controller.task ({c.task!r}) as "
                            f"params['task']; got {c.params['task']!r} as well")
    for key, value in c.params.items():
        values = value if isinstance(value, list) else [value]
        for v in values:
            if not isinstance(v, str) and not math.isfinite(v):
                raise ScenarioError(f"controller.params.{key}: must be finite, got {value}")


def _validate_plant(p) -> None:
    _positive(p.mass_scale, "plant.mass_scale")
    for name in ("damping_scale", "payload_kg"):
        _nonnegative(getattr(p, name), f"plant.{name}")
    _positive(p.coulomb_speed, "plant.coulomb_speed")
    for v in p.coulomb:
        _nonnegative(v, "plant.coulomb")
    d = p.disturbance
    for name in ("amplitude", "phase", "step"):
        if not all(math.isfinite(v) for v in getattr(d, name)):
            raise ScenarioError(f"plant.disturbance.{name}: must be finite")
    _positive(d.frequency_hz, "plant.disturbance.frequency_hz")


def _validate_pick(s) -> None:
    """A pick and place: its segments come from ``pick.tasks`` (no ``interceptions``), grasped from
    above (``controller.task: top_down``) under sampled control; the world and the tasks
    (``pick.config.check_pick_world``, ``pick.tasks.check_tasks``)."""
    from ptint_drake.pick.config import check_pick_parts  # noqa: PLC0415  (pick imports this module)
    from ptint_drake.pick.tasks import check_tasks  # noqa: PLC0415

    if s.interceptions:
        raise ScenarioError("interceptions: a pick scenario's segments come from pick.tasks; leave "
                            "interceptions out")
    if s.measurement is not None:
        raise ScenarioError("measurement: a pick scenario aims at the parts' simulated poses; a camera "
                            "is not modelled there (leave measurement out)")
    if s.controller.task != "top_down":
        raise ScenarioError(f"controller.task: a pick grasps from above: top_down, got {s.controller.task!r}")
    if not s.controller.control_period > 0.0:
        raise ScenarioError("controller.control_period: a pick runs on a discrete plant with contact and "
                            "needs sampled control: set it > 0 (e.g. 0.001)")
    if s.multibody is not None:
        from ptint_drake.pick.config import (DEFAULT_APPROXIMATION, SCENARIO_PLANT_FIELDS,  # noqa: PLC0415
                                             check_plant_settings)

        m = s.multibody
        check_plant_settings(m.time_step, m.discrete_contact_approximation or DEFAULT_APPROXIMATION,
                             m.contact_model, SCENARIO_PLANT_FIELDS)
    check_pick_parts(s.pick)
    check_tasks(s.pick)
    from ptint_drake.pick.tasks import pick_plan  # noqa: PLC0415

    end = pick_plan(s.pick).end
    if s.duration < end:
        raise ScenarioError(f"duration: {s.duration:g} s ends before the pick tasks do ({end:.3g} s)")


def _validate_multibody(m, control_period: float) -> None:
    """``multibody`` (Drake's ``MultibodyPlantConfig``): a finite step >= 0 and positive contact
    parameters; a discrete plant (time_step > 0) needs sampled control, because a continuous
    controller read by a discrete plant is integrated against a state that moves in jumps.
    Drake checks the names (contact model, approximation) when the plant is built."""
    if m is None:
        return
    _nonnegative(m.time_step, "multibody.time_step")
    for name in ("penetration_allowance", "stiction_tolerance"):
        _positive(getattr(m, name), f"multibody.{name}")
    if m.time_step > 0.0 and not control_period > 0.0:
        raise ScenarioError(f"controller.control_period: a discrete plant (multibody.time_step "
                            f"{m.time_step:g} s) needs sampled control: set controller.control_period > 0 "
                            f"(e.g. {m.time_step:g})")


def _validate_simulator(sim) -> None:
    schemes = GetIntegrationSchemes()
    if sim.integration_scheme not in schemes:
        raise ScenarioError(
            f"simulator.integration_scheme: unknown {sim.integration_scheme!r} (one of {', '.join(schemes)})")
    _positive(sim.accuracy, "simulator.accuracy")
    _positive(sim.max_step_size, "simulator.max_step_size")
    if sim.start_time != 0.0:
        raise ScenarioError(
            f"simulator.start_time: must be 0 (scenario times are absolute), got {sim.start_time}")


def _validate_interception(s, i: int, ic) -> None:
    where = f"interceptions[{i}]"
    if not (0.0 < ic.beta < 1.0):
        raise ScenarioError(f"{where}.beta: must be in (0, 1), got {ic.beta}")
    _positive(ic.tf, f"{where}.tf")
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
            _vector3(getattr(t.sinusoid, name), f"{where}.sinusoid.{name}")
        if not math.isfinite(t.sinusoid.omega):
            raise ScenarioError(f"{where}.sinusoid.omega: must be finite")
    elif t.waypoints is not None:
        try:
            WaypointTarget(t.waypoints.time, t.waypoints.position)
        except ValueError as exc:
            raise ScenarioError(f"{where}.waypoints.{exc}") from None
    elif t.ballistic is not None:
        for name in ("start", "velocity", "gravity"):
            _vector3(getattr(t.ballistic, name), f"{where}.ballistic.{name}")
        if not (math.isfinite(t.ballistic.release) and t.ballistic.release >= 0.0):
            raise ScenarioError(f"{where}.ballistic.release: must be >= 0, got {t.ballistic.release}")
    else:
        _vector3(t.linear.start, f"{where}.linear.start")
        _vector3(t.linear.velocity, f"{where}.linear.velocity")
    _validate_orientation(t, where)


def _validate_orientation(t, where: str) -> None:
    """``orientation`` (rpy_deg, rate_deg_s: 3 finite numbers each) and waypoints' ``rpy_deg``
    (one [r, p, y] per sample time); not both."""
    if t.orientation is not None:
        _vector3(t.orientation.rpy_deg, f"{where}.orientation.rpy_deg")
        _vector3(t.orientation.rate_deg_s, f"{where}.orientation.rate_deg_s")
    rpy = t.waypoints.rpy_deg if t.waypoints is not None else []
    if not rpy:
        return
    if t.orientation is not None:
        raise ScenarioError(f"{where}.waypoints.rpy_deg: orientation or rpy_deg, not both")
    if len(rpy) != len(t.waypoints.time):
        raise ScenarioError(f"{where}.waypoints.rpy_deg: one [r, p, y] per time is needed, got {len(rpy)} "
                            f"for {len(t.waypoints.time)} times")
    for k, sample in enumerate(rpy):
        _vector3(sample, f"{where}.waypoints.rpy_deg[{k}]")


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
    if not any(has_orientation(target) for target in s.targets()):
        raise ScenarioError("measurement.rot_noise_deg: no target has an orientation, so the camera measures "
                            "none (give a target an orientation, or remove rot_noise_deg)")
