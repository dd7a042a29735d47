"""Checks of a scenario that need no robot model (the model-dependent ones — reachability,
effort limits — run before the simulation, in the worlds); each failure is a ``ScenarioError``
whose one-line message names the field.  The blocks every scenario has are checked here; the
world's own (``interceptions`` or ``pick``) by its world (``worlds.registry.world_of``)."""

import math

from pydrake.systems.analysis import GetIntegrationSchemes

from ptint_drake.config.controller import default_pinv_damping
from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.fields import nonnegative, positive
from ptint_drake.controllers import CONTROLLERS, REGISTRY, known_type, plugin
from ptint_drake.verdict.metrics import validate_criteria
from ptint_drake.robot.plant import resolve_model
from ptint_drake.systems.perception.camera import validate_measurement
from ptint_drake.controllers.ptsmc.sliding_surface import SIGMA_POLICIES, SWITCHING_LAWS
from ptint_drake.systems.task.error import TASKS
from ptint_drake.worlds.registry import TARGET_KINDS, world_of

__all__ = ["IMPLEMENTATIONS", "TARGET_KINDS", "ScenarioError", "validate"]

IMPLEMENTATIONS = ("fused", "blocks")


def validate(s) -> None:
    """Checks that need no robot model (the model-dependent ones live in ``robot``); ``robot.model``
    must name a bundled model or an existing file (not parsed here)."""
    positive(s.duration, "duration")
    resolve_model(s.robot.model)  # a bundled name or a file: named before any study fans out
    if s.controller.pinv_damping is None:  # left out: one start angle per joint (checked on the model)
        s.controller.pinv_damping = default_pinv_damping(s.controller.task, len(s.robot.initial_q_deg))
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
        positive(getattr(s.limits, name), f"limits.{name}")
    nonnegative(s.limits.singular_value_warning, "limits.singular_value_warning")
    _validate_simulator(s.simulator)
    world_of(s).validate(s)


def _validate_controller(c) -> None:
    for name in ("K", "Lambda", "k", "k_hold", "epsilon", "delta"):
        positive(getattr(c, name), f"controller.{name}")
    for name in ("alpha_hold", "pinv_damping", "null_space_damping", "null_space_rate",
                 "null_space_limit_margin_deg"):
        nonnegative(getattr(c, name), f"controller.{name}")
    if not known_type(c.type):
        raise ScenarioError(f"controller.type: must be one of {', '.join(CONTROLLERS)}, or {plugin.FORM}, "
                            f"got {c.type!r}")
    for name, value, allowed in (("switching", c.switching, SWITCHING_LAWS),
                                 ("implementation", c.implementation, IMPLEMENTATIONS),
                                 ("sigma_policy", c.sigma_policy, SIGMA_POLICIES)):
        if value not in allowed:
            raise ScenarioError(f"controller.{name}: must be one of {', '.join(allowed)}, got {value!r}")
    if c.switching != "sign":
        positive(c.phi, "controller.phi")
    if c.task not in TASKS:
        raise ScenarioError(f"controller.task: must be one of {', '.join(TASKS)}, got {c.task!r}")
    if c.task != "position" and c.type != "ptsmc" and not plugin.is_plugin(c.type):
        raise ScenarioError(f"controller.task: {c.task!r} is implemented by ptsmc (and a plugin gets it in "
                            f"params['task']), not {c.type!r}")
    positive(c.rot_scale, "controller.rot_scale")
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
    positive(p.mass_scale, "plant.mass_scale")
    for name in ("damping_scale", "payload_kg"):
        nonnegative(getattr(p, name), f"plant.{name}")
    positive(p.coulomb_speed, "plant.coulomb_speed")
    for v in p.coulomb:
        nonnegative(v, "plant.coulomb")
    d = p.disturbance
    for name in ("amplitude", "phase", "step"):
        if not all(math.isfinite(v) for v in getattr(d, name)):
            raise ScenarioError(f"plant.disturbance.{name}: must be finite")
    positive(d.frequency_hz, "plant.disturbance.frequency_hz")


def _validate_multibody(m, control_period: float) -> None:
    """``multibody`` (Drake's ``MultibodyPlantConfig``): a finite step >= 0 and positive contact
    parameters; a discrete plant (time_step > 0) needs sampled control, because a continuous
    controller read by a discrete plant is integrated against a state that moves in jumps.
    Drake checks the names (contact model, approximation) when the plant is built."""
    if m is None:
        return
    nonnegative(m.time_step, "multibody.time_step")
    for name in ("penetration_allowance", "stiction_tolerance"):
        positive(getattr(m, name), f"multibody.{name}")
    if m.time_step > 0.0 and not control_period > 0.0:
        raise ScenarioError(f"controller.control_period: a discrete plant (multibody.time_step "
                            f"{m.time_step:g} s) needs sampled control: set controller.control_period > 0 "
                            f"(e.g. {m.time_step:g})")


def _validate_simulator(sim) -> None:
    schemes = GetIntegrationSchemes()
    if sim.integration_scheme not in schemes:
        raise ScenarioError(
            f"simulator.integration_scheme: unknown {sim.integration_scheme!r} (one of {', '.join(schemes)})")
    positive(sim.accuracy, "simulator.accuracy")
    positive(sim.max_step_size, "simulator.max_step_size")
    if sim.start_time != 0.0:
        raise ScenarioError(
            f"simulator.start_time: must be 0 (scenario times are absolute), got {sim.start_time}")
