"""Scenario files (docs/scenarios.md): the typed schema and loading.

A scenario is one YAML mapping loaded with Drake's ``yaml_load_typed`` into
``Scenario``; unknown keys are rejected; the checks live in ``validation``, the
YAML writing and error messages in ``scenario_yaml``.  ``simulator`` is Drake's own
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
- ``controller.type``: ``ptsmc`` (the paper's), another controller of the registry
  (``controllers.REGISTRY``), or a user's own ``module:Class`` with its ``params``
  (``controllers.plugin``);
- ``controller.control_period``: 0 s, continuous control; > 0 s runs the controller
  sampled with its torque held between samples (``controllers.hold``), as on a real drive;
- ``multibody``: absent, the continuous plant integrated with ``simulator``; Drake's own
  ``MultibodyPlantConfig`` (``time_step``, ``discrete_contact_approximation``, …) builds the
  plant with those settings (``robot.make_plant``); a discrete plant needs sampled control;
- ``plant``: scale factors for link masses/inertias and joint damping, used
  to show that the model-free controller needs no retuning (all 1 by default);
  ``apply_variant`` gives the named plant variants (nominal, mass_xF, payload_Mkg);
- ``criteria``: the scenario's pass criteria (``metrics.Criteria``).
"""


import copy
import math
from dataclasses import dataclass, field, make_dataclass
from importlib import resources
from pathlib import Path
from typing import Dict, List, Optional, Union

from pydrake.common.yaml import yaml_load_typed
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig

from ptint_drake.controllers import REGISTRY, plugin
from ptint_drake.metrics import Criteria
from ptint_drake.pick.tasks import PickConfig, pick_plan
from ptint_drake.scenario_yaml import dump_dataclass, dump_yaml, yaml_error
from ptint_drake.systems.camera import MeasurementConfig
from ptint_drake.systems.gains import ControllerGains
from ptint_drake.systems.orientation import OrientedTarget, SlerpOrientation, SpinningOrientation
from ptint_drake.systems.schedule import Schedule, Segment
from ptint_drake.systems.targets import BallisticTarget, LinearTarget, SinusoidTarget, WaypointTarget
from ptint_drake.validation import TARGET_KINDS, ScenarioError, validate

__all__ = ["TARGET_KINDS", "ScenarioError", "Scenario", "dump_dataclass", "dump_yaml",
           "load_scenario", "parse_scenario", "parse_with_overrides", "apply_variant", "check_variants",
           "validate"]


@dataclass
class RobotConfig:
    model: str = "rvm1"  # a bundled model name or a path to a URDF/SDFormat file
    end_effector: str = "tool"  # frame whose origin is the interception point
    initial_q_deg: List[float] = field(default_factory=lambda: [22.5, 45.0, 30.0])


ParamValue = Union[List[float], float, int, str]  # a plugin's setting (the order is Drake YAML's)


def _controller_config() -> type:
    """``ControllerConfig``: the paper's gains flat (``ControllerGains``, shared by ``smc``), which
    controller runs (``type``), a plugin's ``params``, and one block per registered controller
    with settings of its own (``controller.pd``, ``controller.smc``, …: from the registry)."""
    own = [(e.name, e.config, field(default_factory=e.config)) for e in REGISTRY.values() if e.config]
    cls = make_dataclass("ControllerConfig", [
        # a plain field rather than a tagged YAML variant, so that ``--set controller.type=pd``
        # works and an untagged mapping stays the paper's controller
        ("type", str, field(default="ptsmc")),  # a name of controllers.REGISTRY, or "module:Class"
        ("implementation", str, field(default="fused")),  # ptsmc: "fused" one LeafSystem, or "blocks"
        ("params", Dict[str, ParamValue], field(default_factory=dict)),  # a plugin's settings
        ("control_period", float, field(default=0.0)),  # s: > 0 sampled, torque held between samples
        *own], bases=(ControllerGains,), namespace={"__module__": __name__})
    cls.__doc__ = _controller_config.__doc__
    return cls


ControllerConfig = _controller_config()


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
    # not List[List[float]]: yaml_load_typed cannot build a typing.List inside a list
    position: list[list[float]] = field(default_factory=list)
    # optional: the object's roll-pitch-yaw (degrees) at each time, slerped between samples
    rpy_deg: list[list[float]] = field(default_factory=list)


@dataclass
class OrientationConfig:
    """The object frame's orientation: Drake RollPitchYaw (R = Rz·Ry·Rx, degrees) at t = 0 and a
    constant world-frame angular velocity (deg/s)."""

    rpy_deg: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    rate_deg_s: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])


@dataclass
class BallisticConfig:
    """A thrown object: free flight from ``release`` (s) at ``start`` (m) with ``velocity`` (m/s)."""

    start: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    velocity: List[float] = field(default_factory=lambda: [0.0, 0.0, 0.0])
    gravity: List[float] = field(default_factory=lambda: [0.0, 0.0, -9.81])  # m/s²
    release: float = 0.0


@dataclass
class TargetConfig:
    sinusoid: Optional[SinusoidConfig] = None
    linear: Optional[LinearConfig] = None
    waypoints: Optional[WaypointsConfig] = None
    orientation: Optional[OrientationConfig] = None
    ballistic: Optional[BallisticConfig] = None


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

    mass_scale: float = 1.0  # every link's mass and inertia and every rotor inertia × this
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
    multibody: Optional[MultibodyPlantConfig] = None  # None: the continuous plant (robot.make_plant)
    measurement: Optional[MeasurementConfig] = None  # None: no camera, the analytic target
    limits: LimitsConfig = field(default_factory=LimitsConfig)
    simulator: SimulatorConfig = field(default_factory=_default_simulator)
    criteria: Criteria = field(default_factory=Criteria)
    # a pick and place (``pick.tasks``): the world and the tasks, whose segments replace
    # ``interceptions`` (None: an interception scenario)
    pick: Optional[PickConfig] = None
    name: str = ""

    def schedule(self) -> Schedule:
        """The interceptor's segments: ``interceptions``, or the pick tasks' (``pick_plan``)."""
        if self.pick is not None:
            return pick_plan(self.pick).schedule
        return Schedule([Segment(i.start, i.tf, i.beta) for i in self.interceptions])

    def targets(self) -> list:
        return [make_target(i.target) for i in self.interceptions]


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


def bundled_scenarios() -> "list[str]":
    """Names of the scenarios shipped in ``ptint_drake/scenarios`` (``ptint list``)."""
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
    plugin.remember_folder(path.parent)  # a plugin controller's module may sit beside the file
    return path.stem, path.read_text()


def load_scenario(name_or_file: str) -> Scenario:
    """The validated ``Scenario`` of a bundled name or a YAML file (``ScenarioError`` if bad)."""
    name, text = scenario_text(name_or_file)
    return parse_scenario(text, name)


def parse_scenario(text: str, name: str = "scenario") -> Scenario:
    """Parse and validate YAML text; raises ScenarioError naming the field."""
    try:
        scenario = yaml_load_typed(schema=Scenario, data=text)
    except Exception as exc:  # yaml_load_typed raises several types; keep one line
        raise ScenarioError(yaml_error(text, Scenario, exc)) from None
    if not scenario.name:
        scenario.name = name
    validate(scenario)
    return scenario


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


def check_variants(scenario: Scenario, variants) -> None:
    """A one-line ScenarioError naming the first variant ``apply_variant`` does not know,
    before any run starts."""
    for variant in variants:
        apply_variant(scenario, variant)


def parse_with_overrides(text: str, overrides, name: str = "scenario") -> Scenario:
    """The validated scenario of YAML ``text`` with ``overrides`` applied: ``key=value``
    strings as ``--set`` takes them (``["interceptions[0].tf=1.2", "controller.type=pd"]``,
    values are YAML) or a YAML mapping text (``"controller: {K: 40}"``); see ``LoadedScenario``."""
    return LoadedScenario.parse(text, name, overrides).scenario


@dataclass(frozen=True)
class LoadedScenario:
    """A scenario parsed once for a command: ``name`` (the bundled name or file stem, the
    fallback of ``scenario.name``), ``text`` (its YAML with every override applied: what
    worker processes rebuild it from) and the validated ``scenario`` (not to be mutated)."""

    name: str
    text: str
    scenario: Scenario

    @classmethod
    def load(cls, name_or_file: str, overrides=()) -> "LoadedScenario":
        """A bundled scenario name or a scenario file, with ``overrides`` (``parse``)."""
        name, text = scenario_text(name_or_file)
        return cls.parse(text, name, overrides)

    @classmethod
    def parse(cls, text: str, name: str = "scenario", overrides=()) -> "LoadedScenario":
        """YAML ``text`` with ``overrides`` applied (``scenario_yaml.override_text``), validated.
        A bad override is one line naming its key (``--set KEY: ...``) or, when the file
        itself is valid, the field it made invalid (``--set: FIELD: ...``)."""
        from ptint_drake.scenario_yaml import override_text  # noqa: PLC0415

        changed = override_text(text, overrides)
        if changed is text:
            return cls(name, text, parse_scenario(text, name))
        try:
            return cls(name, changed, parse_scenario(changed, name))
        except ScenarioError as exc:
            parse_scenario(text, name)  # an error of the file itself is reported as such
            raise ScenarioError(f"--set: {exc}") from None
