"""Scenario files (SPEC section 5.2): a typed schema, loading and validation.

A scenario is one YAML mapping loaded with Drake's ``yaml_load_typed`` into
``Scenario``; unknown keys are rejected.  ``simulator`` is Drake's own
``SimulatorConfig``.  ``load_scenario`` accepts a bundled name (see
``bundled_scenarios``) or a file path, and raises ``ScenarioError`` with a
one-line message that names the offending field.

Defaults are the paper's: gains K = 50, Λ = 5, k = 3, ϵ = δ = 1e-6 (section
3.1), the RV-M1 start pose θ = (22.5°, 45°, 30°).  Choices the paper leaves
open, with their defaults:

- ``controller.switching``: ``tanh`` boundary layer of width ``phi`` = 0.01 m/s
  (``sign`` reproduces the paper exactly but slowly);
- ``controller.sigma_policy``: ``keep`` σ across segments (torque stays
  continuous, the learned gravity load is kept);
- ``controller.alpha_hold``: 0 s⁻¹ after tf, as in the paper;
- ``controller.k_hold``: 50 s⁻¹, the decay rate of s_d after tf (``k_hold = k``
  is the paper's formula; see ``sliding_surface`` for why the hold needs it);
- ``controller.implementation``: ``fused`` (one LeafSystem, the fast default) or
  ``blocks`` (the five wired blocks); both compute the same thing;
- ``plant``: scale factors for link masses/inertias and joint damping, used
  to show that the model-free controller needs no retuning (all 1 by default).
"""


import copy
import dataclasses
import math
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import List, Optional

from pydrake.common.yaml import yaml_load_typed
from pydrake.systems.analysis import GetIntegrationSchemes, SimulatorConfig

from ptint_drake.metrics import Criteria, validate_criteria
from ptint_drake.systems.camera import MeasurementConfig, validate_measurement
from ptint_drake.systems.gains import ControllerGains
from ptint_drake.systems.schedule import Schedule, Segment
from ptint_drake.systems.sliding_surface import SIGMA_POLICIES, SWITCHING_LAWS
from ptint_drake.systems.targets import LinearTarget, SinusoidTarget, WaypointTarget


IMPLEMENTATIONS = ("fused", "blocks")
CONTROLLER_TYPES = ("ptsmc",)  # the slot's controllers (controllers.py); ptsmc = the paper's


class ScenarioError(ValueError):
    """A scenario that cannot be run; the message names the field."""


@dataclass
class RobotConfig:
    model: str = "rvm1"  # a bundled model name or a path to a URDF/SDFormat file
    end_effector: str = "tool"  # frame whose origin is the interception point
    initial_q_deg: List[float] = field(default_factory=lambda: [22.5, 45.0, 30.0])


@dataclass
class ControllerConfig(ControllerGains):
    """The paper's gains (shared by ``smc``) and which controller runs (``type``)."""

    type: str = "ptsmc"  # the controller in the slot: ptsmc (the paper's) | pd | smc | ct_quintic
    implementation: str = "fused"  # ptsmc: "fused" one LeafSystem, or "blocks" (the five wired blocks)


@dataclass
class SinusoidConfig:
    center: List[float] = field(default_factory=list)
    amplitude: List[float] = field(default_factory=list)
    omega: float = 0.0
    phase: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class LinearConfig:
    start: List[float] = field(default_factory=list)
    velocity: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class WaypointsConfig:
    """A recorded path: positions (m) at increasing times (s), interpolated C² (cubic spline)."""

    time: List[float] = field(default_factory=list)
    position: list[list[float]] = field(default_factory=list)  # not List[List[float]]: yaml_load_typed cannot build a typing.List inside a list


TARGET_KINDS = ("sinusoid", "linear", "waypoints")


@dataclass
class TargetConfig:
    sinusoid: Optional[SinusoidConfig] = None
    linear: Optional[LinearConfig] = None
    waypoints: Optional[WaypointsConfig] = None


@dataclass
class InterceptionConfig:
    start: float = 0.0
    tf: float = 1.5
    beta: float = 0.75
    target: TargetConfig = field(default_factory=TargetConfig)


@dataclass
class DisturbanceConfig:
    """External joint torque d(t) = amplitude ⊙ sin(2π f t + phase) + step ⊙ [t ≥ step_time]."""

    amplitude: List[float] = field(default_factory=list)  # N·m per joint (empty: none)
    frequency_hz: float = 1.0
    phase: List[float] = field(default_factory=list)  # rad per joint (empty: zeros)
    step: List[float] = field(default_factory=list)  # N·m per joint (empty: none)
    step_time: float = 0.0  # s


@dataclass
class PlantConfig:
    """How the simulated robot differs from its model file (the controller never knows)."""

    mass_scale: float = 1.0  # every link's mass and inertia × this
    damping_scale: float = 1.0  # every joint's viscous damping × this
    payload_kg: float = 0.0  # point-like mass (sphere r 3 cm) welded at the end effector
    coulomb: List[float] = field(default_factory=list)  # N·m per joint: −F tanh(v / coulomb_speed)
    coulomb_speed: float = 0.01  # rad/s, smoothing of the Coulomb law
    disturbance: DisturbanceConfig = field(default_factory=DisturbanceConfig)


@dataclass
class LimitsConfig:
    saturate: bool = True  # clamp torques to the model's effort limits (Drake Saturation)
    max_error: float = 0.5  # m: |e| beyond this stops the run as diverged
    max_joint_speed: float = 50.0  # rad/s (or m/s): beyond this stops the run as diverged
    singular_value_warning: float = 0.02  # m/rad: warn when J's smallest singular value drops below


def _default_simulator() -> SimulatorConfig:
    return SimulatorConfig(integration_scheme="runge_kutta3", accuracy=1.0e-4,
                           max_step_size=0.1, use_error_control=True)


@dataclass
class Scenario:
    duration: float = 3.0
    robot: RobotConfig = field(default_factory=RobotConfig)
    controller: ControllerConfig = field(default_factory=ControllerConfig)
    interceptions: List[InterceptionConfig] = field(default_factory=list)
    plant: PlantConfig = field(default_factory=PlantConfig)
    measurement: MeasurementConfig = field(default_factory=MeasurementConfig)
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    simulator: SimulatorConfig = field(default_factory=_default_simulator)
    criteria: Criteria = field(default_factory=Criteria)
    name: str = ""

    def schedule(self) -> Schedule:
        return Schedule([Segment(i.start, i.tf, i.beta) for i in self.interceptions])

    def targets(self) -> list:
        return [make_target(i.target) for i in self.interceptions]


def make_target(config: TargetConfig):
    if config.sinusoid is not None:
        s = config.sinusoid
        return SinusoidTarget(s.center, s.amplitude, s.omega, s.phase)
    if config.waypoints is not None:
        return WaypointTarget(config.waypoints.time, config.waypoints.position)
    return LinearTarget(config.linear.start, config.linear.velocity)


def bundled_scenarios() -> "list[str]":
    return sorted(p.name[:-5] for p in resources.files("ptint_drake.scenarios").iterdir()
                  if p.name.endswith(".yaml"))


def scenario_text(name_or_file: str) -> "tuple[str, str]":
    """(name, YAML text) of a bundled scenario name or a scenario file."""
    if name_or_file in bundled_scenarios():
        return name_or_file, resources.files("ptint_drake.scenarios").joinpath(
            f"{name_or_file}.yaml").read_text()
    path = Path(name_or_file)
    if not path.is_file():
        raise ScenarioError(
            f"scenario: {name_or_file!r} is neither a bundled scenario "
            f"({', '.join(bundled_scenarios())}) nor a file")
    return path.stem, path.read_text()


def load_scenario(name_or_file: str) -> Scenario:
    name, text = scenario_text(name_or_file)
    return parse_scenario(text, name)


def parse_scenario(text: str, name: str = "scenario") -> Scenario:
    """Parse and validate YAML text; raises ScenarioError naming the field."""
    try:
        scenario = yaml_load_typed(schema=Scenario, data=text)
    except Exception as exc:  # yaml_load_typed raises several types; keep one line
        raise ScenarioError(_yaml_error(text, Scenario, exc)) from None
    if not scenario.name:
        scenario.name = name
    validate(scenario)
    return scenario


def dump_yaml(scenario: "Scenario") -> str:
    """The scenario as YAML text that ``parse_scenario`` reads back to the same scenario."""
    import yaml  # noqa: PLC0415

    return yaml.safe_dump(dump_dataclass(scenario), sort_keys=False)


def _yaml_error(text: str, schema, exc: Exception) -> str:
    """One line for a YAML load failure, naming the field where it can be located."""
    import yaml  # noqa: PLC0415

    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        return f"scenario YAML: malformed{where}: {getattr(err, 'problem', None) or err}"
    found = _locate(raw, schema, "")
    detail = " ".join(str(exc).split())
    return f"{found}" if found else f"scenario YAML: {detail}"


def _locate(raw, schema, path: str) -> Optional[str]:
    """Walk raw YAML data against a dataclass schema; describe the first mismatch."""
    import typing  # noqa: PLC0415

    if dataclasses.is_dataclass(schema):
        if not isinstance(raw, dict):
            return f"{path or 'scenario'}: expected a mapping, got {raw!r}"
        hints = typing.get_type_hints(schema)
        for key, value in raw.items():
            where = f"{path}.{key}" if path else str(key)
            if key not in hints:
                return f"{where}: unknown field (known: {', '.join(hints)})"
            found = _locate(value, hints[key], where)
            if found:
                return found
        return None
    origin = typing.get_origin(schema)
    if origin is typing.Union:
        inner = [a for a in typing.get_args(schema) if a is not type(None)][0]
        return None if raw is None else _locate(raw, inner, path)
    if origin in (list, List):
        if not isinstance(raw, list):
            return f"{path}: expected a list, got {raw!r}"
        item = typing.get_args(schema)[0]
        for i, v in enumerate(raw):
            found = _locate(v, item, f"{path}[{i}]")
            if found:
                return found
        return None
    if schema is float:
        if isinstance(raw, bool) or not isinstance(raw, (int, float)):
            try:
                float(raw)
            except (TypeError, ValueError):
                return f"{path}: expected a number, got {raw!r}"
    if schema is str and not isinstance(raw, str):
        return f"{path}: expected a string, got {raw!r}"
    if schema is SimulatorConfig and not isinstance(raw, dict):
        return f"{path}: expected a mapping, got {raw!r}"
    if schema is SimulatorConfig:
        known = dump_dataclass(SimulatorConfig()).keys()
        for key in raw:
            if key not in known:
                return f"{path}.{key}: unknown field (known: {', '.join(known)})"
    return None


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


def validate(s: Scenario) -> None:
    """Checks that need no robot model (the model-dependent ones live in simulation)."""
    _positive(s.duration, "duration")
    c = s.controller
    for name in ("K", "Lambda", "k", "k_hold", "epsilon", "delta"):
        _positive(getattr(c, name), f"controller.{name}")
    if not (math.isfinite(c.alpha_hold) and c.alpha_hold >= 0.0):
        raise ScenarioError(f"controller.alpha_hold: must be >= 0, got {c.alpha_hold}")
    if c.switching not in SWITCHING_LAWS:
        raise ScenarioError(f"controller.switching: must be one of {', '.join(SWITCHING_LAWS)}, got {c.switching!r}")
    if c.switching != "sign":
        _positive(c.phi, "controller.phi")
    if c.type not in CONTROLLER_TYPES:
        raise ScenarioError(f"controller.type: must be one of {', '.join(CONTROLLER_TYPES)}, got {c.type!r}")
    try:
        validate_criteria(s.criteria)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    if c.implementation not in IMPLEMENTATIONS:
        raise ScenarioError(f"controller.implementation: must be one of {', '.join(IMPLEMENTATIONS)}, "
                            f"got {c.implementation!r}")
    if c.sigma_policy not in SIGMA_POLICIES:
        raise ScenarioError(f"controller.sigma_policy: must be one of {', '.join(SIGMA_POLICIES)}, got {c.sigma_policy!r}")
    _positive(s.plant.mass_scale, "plant.mass_scale")
    for name in ("damping_scale", "payload_kg"):
        _nonnegative(getattr(s.plant, name), f"plant.{name}")
    _positive(s.plant.coulomb_speed, "plant.coulomb_speed")
    for v in s.plant.coulomb:
        _nonnegative(v, "plant.coulomb")
    d = s.plant.disturbance
    for name in ("amplitude", "phase", "step"):
        if not all(math.isfinite(v) for v in getattr(d, name)):
            raise ScenarioError(f"plant.disturbance.{name}: must be finite")
    _positive(d.frequency_hz, "plant.disturbance.frequency_hz")
    try:
        validate_measurement(s.measurement)
    except ValueError as exc:
        raise ScenarioError(str(exc)) from None
    if c.pinv_damping < 0 or not math.isfinite(c.pinv_damping):
        raise ScenarioError(f"controller.pinv_damping: must be >= 0, got {c.pinv_damping}")
    for name in ("max_error", "max_joint_speed"):
        _positive(getattr(s.limits, name), f"limits.{name}")
    _nonnegative(s.limits.singular_value_warning, "limits.singular_value_warning")
    schemes = GetIntegrationSchemes()
    if s.simulator.integration_scheme not in schemes:
        raise ScenarioError(
            f"simulator.integration_scheme: unknown {s.simulator.integration_scheme!r} "
            f"(one of {', '.join(schemes)})")
    _positive(s.simulator.accuracy, "simulator.accuracy")
    _positive(s.simulator.max_step_size, "simulator.max_step_size")
    if s.simulator.start_time != 0.0:
        raise ScenarioError(f"simulator.start_time: must be 0 (scenario times are absolute), got {s.simulator.start_time}")
    if not s.interceptions:
        raise ScenarioError("interceptions: at least one interception is needed")
    for i, ic in enumerate(s.interceptions):
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
        t = ic.target
        kinds = [k for k in TARGET_KINDS if getattr(t, k) is not None]
        if len(kinds) != 1:
            raise ScenarioError(
                f"{where}.target: exactly one of {', '.join(TARGET_KINDS)} is needed, got "
                f"{', '.join(kinds) if kinds else 'none'}")
        if t.sinusoid is not None:
            for name in ("center", "amplitude", "phase"):
                _vector3(getattr(t.sinusoid, name), f"{where}.target.sinusoid.{name}")
            if not math.isfinite(t.sinusoid.omega):
                raise ScenarioError(f"{where}.target.sinusoid.omega: must be finite")
        elif t.waypoints is not None:
            try:
                WaypointTarget(t.waypoints.time, t.waypoints.position)
            except ValueError as exc:
                raise ScenarioError(f"{where}.target.waypoints.{exc}") from None
        else:
            _vector3(t.linear.start, f"{where}.target.linear.start")
            _vector3(t.linear.velocity, f"{where}.target.linear.velocity")


VARIANT_FORMS = "nominal, mass_xF (e.g. mass_x1.5), payload_Mkg (e.g. payload_0.5kg)"


def apply_variant(scenario: Scenario, variant: str) -> Scenario:
    """The scenario on a plant variant (one definition for compare, tune and tests):
    ``nominal`` as is; ``mass_xF``: every link's mass and rotational inertia and every rotor
    inertia × F (friction unchanged); ``payload_Mkg``: a point mass of M kg at the end
    effector.  Returns a copy; ScenarioError naming the variant if it is not one of those."""
    out = copy.deepcopy(scenario)
    try:
        if variant == "nominal":
            return out
        if variant.startswith("mass_x"):
            factor = float(variant[len("mass_x"):])
            if factor > 0 and math.isfinite(factor):
                out.plant.mass_scale *= factor
                return out
        elif variant.startswith("payload_") and variant.endswith("kg"):
            mass = float(variant[len("payload_"):-2])
            if mass >= 0 and math.isfinite(mass):
                out.plant.payload_kg += mass
                return out
    except ValueError:
        pass
    raise ScenarioError(f"variant: unknown plant variant {variant!r} (use {VARIANT_FORMS})")


def dump_dataclass(obj) -> dict:
    """A plain dict of a scenario (SimulatorConfig included), for reports."""
    if dataclasses.is_dataclass(obj):
        return {f.name: dump_dataclass(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, SimulatorConfig):
        return {k: getattr(obj, k) for k in (
            "integration_scheme", "max_step_size", "accuracy", "use_error_control",
            "start_time", "target_realtime_rate", "publish_every_time_step")}
    if isinstance(obj, list):
        return [dump_dataclass(v) for v in obj]
    return obj


def parse_with_overrides(text: str, overrides: str, name: str = "scenario") -> Scenario:
    """Parse ``text``, then merge the YAML mapping ``overrides`` over it, then validate."""
    base = parse_scenario(text, name)
    try:
        scenario = yaml_load_typed(schema=Scenario, data=overrides, defaults=base)
    except Exception as exc:
        raise ScenarioError("--set " + _yaml_error(overrides, Scenario, exc)) from None
    validate(scenario)
    return scenario
