"""The scenario schema (docs/scenarios.md): plain dataclasses that Drake's ``yaml_load_typed``
fills from a scenario's YAML mapping, unknown keys rejected.  Nothing here loads, checks or
runs anything: loading and validation are ``ptint_drake.simulation.scenario`` and
``ptint_drake.simulation.validation``,
the worlds that run a scenario are ``ptint_drake.worlds``.  ``simulator`` is Drake's own
``SimulatorConfig``, ``multibody`` Drake's ``MultibodyPlantConfig``.

Defaults are the paper's: gains K = 50, Λ = 5, k = 3, ϵ = δ = 1e-6 (section 3.1), the RV-M1
start pose θ = (22.5°, 45°, 30°).  Choices the paper leaves open are listed in
``ptint_drake.simulation.scenario``'s docstring.  (No postponed annotations: ``yaml_load_typed`` reads
the field types.)
"""

from dataclasses import dataclass, field
from typing import ClassVar, Dict, List, Optional

from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig

from ptint_drake.config.controller import ControllerConfig, ParamValue
from ptint_drake.config.criteria import Criteria
from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.config.catch import CatchConfig
from ptint_drake.config.pick import PickConfig


@dataclass
class WorldConfig:
    """A world of the user's own (``worlds.registry``): ``type`` = ``"module:Class"``, a
    ``worlds.World`` subclass in the user's file (looked up like a plugin controller: the
    scenario's folder, the current directory, ``PYTHONPATH``), constructed with no arguments;
    ``params``: its settings, which it reads from the scenario."""

    type: str = ""
    params: Dict[str, ParamValue] = field(default_factory=dict)


@dataclass
class RobotConfig:
    model: str = "rvm1"  # a bundled model name or a path to a URDF/SDFormat file
    end_effector: str = "tool"  # frame whose origin is the interception point
    initial_q_deg: List[float] = field(default_factory=lambda: [22.5, 45.0, 30.0])


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
    # m: |e| growing this far beyond its value at the segment's start stops the run as diverged (a
    # limit on growth, not size: an object thrown from 1.4 m away starts far and is still caught)
    max_error: float = 0.5
    max_joint_speed: float = 50.0  # rad/s (or m/s): beyond this stops the run as diverged
    singular_value_warning: float = 0.02  # m/rad: warn when J's smallest singular value drops below


def default_simulator() -> SimulatorConfig:
    """Error-controlled RK3 at accuracy 1e-4, steps of at most 0.1 s (the scenarios' default)."""
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
    simulator: SimulatorConfig = field(default_factory=default_simulator)
    criteria: Criteria = field(default_factory=Criteria)
    # a pick and place (``worlds.pick``): the world and the tasks, whose segments replace
    # ``interceptions`` (None: an interception scenario)
    pick: Optional[PickConfig] = None
    # a thrown ball caught in the hand (``worlds.catch``, issue 46)
    catch: Optional[CatchConfig] = None
    # a world of the user's own (``WorldConfig``; None: the world of the blocks above)
    world: Optional[WorldConfig] = None
    name: str = ""
    # not a YAML field: the folder of the file the scenario was loaded from, where a plugin
    # controller's module is looked for first (``controllers.plugin``); set by loading, carried
    # with the object (copies, pickles to worker processes)
    plugin_folders: ClassVar[tuple] = ()
