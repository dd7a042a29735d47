"""What every controller in the slot is wired to, and what it hands back.

``ControllerSlot`` is the station seen from a controller: the ports it connects to (``state``
out of the station, ``actuation`` into it), the plant for its kinematics, the end-effector
frame, the schedule of segments, and the start posture.  ``TargetView`` is the target as the
controller is *allowed* to see it:

- no ``measurement`` (or ``estimator: none``): the analytic targets, as objects in
  ``analytic`` and, when a controller asks for it, as a ``TargetSource`` port;
- with a camera: only what one camera and one estimator per object (``auto`` or a
  hand-set Kalman filter) make of the station's true object positions (``analytic`` is None),
  and, for objects with an orientation, what ``rotation_estimator`` makes of the camera's
  orientation samples (the station's ``object_rotations``).

The station's true target never reaches a controller directly.  The port is built on first
use, so a controller that evaluates the analytic targets itself (the fused interceptor) adds
no system for it.

``ControllerHandles`` is what an ``Add…`` function returns: the ports to log at every
integrator step, how to turn those logs into telemetry (named arrays, rows = samples; at
least ``tau``), lines for the run's output, and whether the controller used the model.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Callable, Optional

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import Frame
from pydrake.systems.framework import DiagramBuilder, InputPort, OutputPort

from ptint_drake.robot.plant import nominal_plant
from ptint_drake.systems.estimation.kalman import AddCameraEstimators, CameraEstimators
from ptint_drake.systems.estimation.rotation_estimator import AddRotationEstimators
from ptint_drake.systems.perception.part_pose_estimator import FIT_NOISE_STD, AddRgbdPerception
from ptint_drake.systems.task.orientation import has_orientation
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET
from ptint_drake.systems.task.targets import TargetSource

if TYPE_CHECKING:
    from ptint_drake.config.schema import Scenario


@dataclass
class ControllerHandles:
    """What the slot added: the ports to log every step, how to turn those logs into
    telemetry (a dict of arrays, rows = samples), and lines for the run's output."""

    name: str
    log_ports: dict
    telemetry: Callable[[dict], dict]
    notes: list = field(default_factory=list)
    model_based: bool = False
    system: object = None
    plugin: bool = False  # a user's controller: an exception inside it fails the run, not the program


@dataclass
class ControllerSlot:
    """The station as a controller sees it (see the module docstring)."""

    builder: DiagramBuilder
    plant: MultibodyPlant  # the simulated plant, for kinematics (model-free controllers)
    frame: Frame  # the end effector: its origin is the interception point
    schedule: Schedule
    state: OutputPort  # the arm's [q; v]
    actuation: InputPort  # one torque per actuator, in actuator order (the hold's input when sampled)
    initial_q: np.ndarray  # the start posture (rad / m)
    scenario: "Scenario"
    targets: list = field(default_factory=list)  # the world's analytic objects ([] where none)

    def nominal_plant(self) -> MultibodyPlant:
        """The arm's model file as written (``robot.nominal_plant``): what a model-based
        controller is allowed to know."""
        return nominal_plant(self.scenario)

    def connect(self, system, target: "TargetView") -> OutputPort:
        """Wire a controller with ports ``state``, ``target`` in and ``u`` out (and
        ``target_rotation`` when it declares one); returns the target port it was given."""
        self.builder.Connect(self.state, system.GetInputPort("state"))
        self.builder.Connect(system.GetOutputPort("u"), self.actuation)
        port = target.port()
        self.builder.Connect(port, system.GetInputPort("target"))
        if system.HasInputPort("target_rotation"):
            self.builder.Connect(target.rotation_port(), system.GetInputPort("target_rotation"))
        return port


class TargetView:
    """The target as the controller may see it: ``analytic`` (the target objects, or None with
    a camera), ``port()`` ([x_r, ẋ_r, ẍ_r] of the active segment, built on first use) and
    ``rotation_port()`` ([R_r, ω_r, ω̇_r], ``signals.TARGET_ROTATION``: the analytic
    orientation, or with a camera what ``rotation_estimator`` makes of the camera's
    orientation samples when a target has an orientation).  With a camera both ports come
    from one set of cameras (``camera_estimators``).  ``schedule`` and ``targets``: the world's
    segments and the objects' true motions (which only the cameras see in camera mode)."""

    def __init__(self, builder: DiagramBuilder, station_system, scenario: "Scenario", schedule: Schedule,
                 targets: list):
        self._builder, self._station, self._scenario = builder, station_system, scenario
        self._schedule, self._targets = schedule, targets
        self.analytic = targets if uses_analytic_targets(scenario) else None
        self._port: Optional[OutputPort] = None
        self._rotation_port: Optional[OutputPort] = None
        self._cameras: Optional[CameraEstimators] = None

    def port(self) -> OutputPort:
        if self._port is None:
            if self.analytic is not None:
                source = self._builder.AddNamedSystem("target_view",
                                                      TargetSource(self._schedule, self.analytic))
                self._port = source.GetOutputPort("target")
            else:
                self._port = self.camera_estimators().target_port
        return self._port

    def camera_estimators(self) -> CameraEstimators:
        """The cameras and position estimators (built on first use; camera mode only)."""
        if self._cameras is None:
            self._cameras = camera_estimators(self._builder, self._station, self._scenario, self._schedule,
                                              self._targets)
        return self._cameras

    def rotation_port(self) -> OutputPort:
        if self._rotation_port is None:
            if self.analytic is None and measures_orientation(self._scenario, self._targets):
                self._rotation_port = AddRotationEstimators(
                    self._builder, cameras=self.camera_estimators().cameras,
                    schedule=self._schedule, config=self._scenario.measurement).rotation_port
            else:  # the analytic orientation (with a camera: no target has one, a fixed frame)
                source = self._builder.AddNamedSystem("target_rotation_view", TargetSource(
                    self._schedule, self.analytic or self._targets))
                self._rotation_port = source.GetOutputPort("target_rotation")
        return self._rotation_port


def uses_analytic_targets(scenario: "Scenario") -> bool:
    """True unless a camera and an estimator are in the loop."""
    return scenario.measurement is None or scenario.measurement.estimator == "none"


def measures_orientation(scenario: "Scenario", targets: list) -> bool:
    """True when a camera is in the loop and one of ``targets`` carries an orientation: the
    cameras then measure the objects' orientations too (``measurement.rot_noise_deg``)."""
    return not uses_analytic_targets(scenario) and any(has_orientation(t) for t in targets)


def camera_estimators(builder: DiagramBuilder, station_system, scenario: "Scenario", schedule: Schedule,
                      targets: list) -> CameraEstimators:
    """One camera + position estimator per object fed by the station's true object positions
    (and orientations when ``measures_orientation``), in view before t = 0 (``targets``: the
    objects' motions before t = 0).  With ``measurement.sensor: rgbd`` the samples are the part
    poses fitted to the station's ``depth_image`` (``perception.AddRgbdPerception``; the motions
    give only the belts when none are configured)."""
    if scenario.measurement.sensor == "rgbd":
        seen, _ = AddRgbdPerception(builder, station_system.GetOutputPort("depth_image"),
                                    scenario.measurement, targets, scenario.duration)
        config = scenario.measurement
        if not config.noise_std:  # the fits' own noise, not the pose sensor's formula
            config = dataclasses.replace(config, noise_std=FIT_NOISE_STD)
        return AddCameraEstimators(builder, schedule=schedule, config=config, cameras=seen)
    rotations = (station_system.GetOutputPort("object_rotations") if measures_orientation(scenario, targets)
                 else None)
    return AddCameraEstimators(builder, objects_port=station_system.GetOutputPort("objects"),
                               schedule=schedule, config=scenario.measurement,
                               histories=targets, rotations_port=rotations)


def target_columns(target_log: np.ndarray) -> dict:
    """x_r, ẋ_r, ẍ_r of a logged target port (what the controller saw)."""
    return {"x_r": target_log[:, TARGET.x], "xdot_r": target_log[:, TARGET.xdot],
            "xddot_r": target_log[:, TARGET.xddot]}


def telemetry_handles(name: str, system, target: OutputPort, notes, model_based: bool = False
                      ) -> ControllerHandles:
    """Handles of a controller with a ``telemetry`` port named by its ``layout`` (the
    baselines): that port and the target it saw are logged at every step."""
    ports = {"telemetry": system.GetOutputPort("telemetry"), "target": target}
    layout = system.layout

    def telemetry(logs: dict) -> dict:
        out = {key: logs["telemetry"][:, part] for key, part in layout.items()}
        out |= target_columns(logs["target"])
        return out

    return ControllerHandles(name, ports, telemetry, notes, model_based, system)
