"""The bottom layer: the scenario schema (``schema``), its blocks (``controller``,
``measurement``, ``criteria``, ``pick``), the one error type (``errors``) and the YAML text
helpers (``yaml_io``).  It imports nothing of the package above it."""

from ptint_drake.config.controller import (ControllerConfig, ControllerGains, CtQuinticConfig, PDConfig,
                                           SmcOptions)
from ptint_drake.config.criteria import Criteria
from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.config.pick import PickConfig, PickWorldConfig
from ptint_drake.config.schema import (BallisticConfig, DisturbanceConfig, InterceptionConfig, LimitsConfig,
                                       LinearConfig, OrientationConfig, PlantConfig, RobotConfig, Scenario,
                                       SinusoidConfig, TargetConfig, WaypointsConfig, default_simulator)

__all__ = ["BallisticConfig", "ControllerConfig", "ControllerGains", "Criteria", "CtQuinticConfig",
           "DisturbanceConfig", "InterceptionConfig", "LimitsConfig", "LinearConfig", "MeasurementConfig",
           "OrientationConfig", "PDConfig", "PickConfig", "PickWorldConfig", "PlantConfig", "RobotConfig",
           "Scenario", "ScenarioError", "SinusoidConfig", "SmcOptions", "TargetConfig", "WaypointsConfig",
           "default_simulator"]
