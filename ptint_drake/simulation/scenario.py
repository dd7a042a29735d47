"""Scenario files (docs/scenarios.md): loading, overrides and validation over the schema.

A scenario is one YAML mapping loaded with Drake's ``yaml_load_typed`` into
``Scenario`` (the schema, ``config.schema``, re-exported here); unknown keys are rejected; the
checks live in ``validation``, the YAML writing and error messages in ``config.yaml_io``.
``simulator`` is Drake's own
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
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from pydrake.common.yaml import yaml_load_typed

from ptint_drake.config.controller import ControllerConfig, ParamValue
from ptint_drake.config.criteria import Criteria
from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import (BallisticConfig, DisturbanceConfig, InterceptionConfig, LimitsConfig,
                                       LinearConfig, OrientationConfig, PlantConfig, RobotConfig, Scenario,
                                       SinusoidConfig, TargetConfig, WaypointsConfig, default_simulator)
from ptint_drake.config.yaml_io import dump_dataclass, dump_yaml, yaml_error
from ptint_drake.simulation.validation import TARGET_KINDS, validate

__all__ = ["TARGET_KINDS", "BallisticConfig", "ControllerConfig", "Criteria", "DisturbanceConfig",
           "InterceptionConfig", "LimitsConfig", "LinearConfig", "LoadedScenario", "OrientationConfig",
           "ParamValue", "PlantConfig", "RobotConfig", "Scenario", "ScenarioError", "SinusoidConfig",
           "TargetConfig", "WaypointsConfig", "apply_variant", "bundled_scenarios", "check_variants",
           "default_simulator", "dump_dataclass", "dump_yaml", "load_scenario", "parse_scenario",
           "parse_with_overrides", "scenario_folders", "scenario_summary", "scenario_text", "validate"]


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
    return path.stem, path.read_text()


def scenario_summary(text: str) -> str:
    """A scenario file's one-line summary (``ptint list``): its first line when that is a
    comment, without the ``#`` (empty otherwise).  The bundled files keep it one whole
    sentence, with the details in the comment paragraphs below it."""
    first = text.splitlines()[0] if text else ""
    return first.lstrip("#").strip() if first.startswith("#") else ""


def scenario_folders(name_or_file: str) -> tuple:
    """The folder a plugin controller's module may sit in beside a scenario file (none for a
    bundled scenario)."""
    if name_or_file in bundled_scenarios() or not Path(name_or_file).is_file():
        return ()
    return (str(Path(name_or_file).resolve().parent),)


def load_scenario(name_or_file: str) -> Scenario:
    """The validated ``Scenario`` of a bundled name or a YAML file (``ScenarioError`` if bad)."""
    name, text = scenario_text(name_or_file)
    return parse_scenario(text, name, scenario_folders(name_or_file))


def parse_scenario(text: str, name: str = "scenario", folders: tuple = ()) -> Scenario:
    """Parse and validate YAML text; raises ScenarioError naming the field.  ``folders``: where
    a plugin controller's module is looked for first (``Scenario.plugin_folders``)."""
    try:
        scenario = yaml_load_typed(schema=Scenario, data=text)
    except Exception as exc:  # yaml_load_typed raises several types; keep one line
        raise ScenarioError(yaml_error(text, Scenario, exc)) from None
    if not scenario.name:
        scenario.name = name
    if folders:
        scenario.plugin_folders = tuple(folders)
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
    worker processes rebuild it from), the validated ``scenario`` (not to be mutated) and the
    ``folders`` a plugin controller's module is looked for in (the scenario file's; a study hands
    them to its workers)."""

    name: str
    text: str
    scenario: Scenario
    folders: tuple = ()

    @classmethod
    def load(cls, name_or_file: str, overrides=()) -> "LoadedScenario":
        """A bundled scenario name or a scenario file, with ``overrides`` (``parse``)."""
        name, text = scenario_text(name_or_file)
        return cls.parse(text, name, overrides, scenario_folders(name_or_file))

    @classmethod
    def parse(cls, text: str, name: str = "scenario", overrides=(), folders: tuple = ()) -> "LoadedScenario":
        """YAML ``text`` with ``overrides`` applied (``scenario_yaml.override_text``), validated.
        A bad override is one line naming its key (``--set KEY: ...``) or, when the file
        itself is valid, the field it made invalid (``--set: FIELD: ...``)."""
        from ptint_drake.config.yaml_io import override_text  # noqa: PLC0415

        changed = override_text(text, overrides)
        if changed is text:
            return cls(name, text, parse_scenario(text, name, folders), tuple(folders))
        try:
            return cls(name, changed, parse_scenario(changed, name, folders), tuple(folders))
        except ScenarioError as exc:
            parse_scenario(text, name, folders)  # an error of the file itself is reported as such
            raise ScenarioError(f"--set: {exc}") from None
