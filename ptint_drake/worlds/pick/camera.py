"""The pick world seen through an RGB-D camera (issue 34): what the approach and the grasp aim at
when ``measurement.sensor`` is ``rgbd``.

In the station (``station.MakePickStation(config, measurement)``) ``AddPickCamera`` adds Drake's
``RgbdSensor`` (``perception.rgbd_camera``) rendering the station's own ``SceneGraph`` — the arm,
the gripper, the belts, the parts and the tray as the plant poses them, so the arm occludes — and
exports ``color_image`` and ``depth_image``.  Outside the station ``AddPartEstimates`` adds the
perception (``perception.MakeRgbdPerception``: its only input is the depth image; it knows the
camera's configured intrinsics and pose, the belts' configured top surfaces and the parts' shape
and size), one position estimator per part (``kalman.AddCameraEstimators``: ``auto`` by default)
and one rotation filter per part (``rotation_estimator.AddRotationEstimators``), and
``EstimatedParts``, whose ``part_k_pose`` / ``part_k_rotation`` have the layouts of
``part_pose.PartPoses``' and replace them as ``PickTargets``' inputs.  The simulated poses stay
with the metrics.

``EstimatedParts``: for part k, once its position estimator has a sample (its output is no
longer zero), the estimate with the conveyor's constraint — the centre's height is the belt's top
plus half the part's height, its velocity along the belt, no acceleration (all configured): over the ~0.8 s
the arm hides the part before its grasp the ``auto`` estimator's acceleration term otherwise
extrapolates the last fits' jitter (measured on conveyor_pick_place_rgbd seed 1: z 18 mm low at
the grasp) — and the filtered yaw; before, the part's *nominal* pose — its configured offset, the middle
of its lateral range, its configured yaw (0 when random), moving at its belt's speed
(``placement.nominal_parts``: configuration only).  ``seen`` (n): 1 for each part seen so far.
The world reads ``seen`` and the perception's ``fit_counts`` at each descend's start: a part never
seen, or fitted fewer than ``MIN_FITS`` times, is not grasped (``world.PickRun``: ``pick k: part
not seen``).

The perceived belts: ``measurement.camera.belts`` when given; otherwise each pick belt's top
surface (its centre at t = 0, its direction and length) ``BELT_MARGIN`` wider on each side than
the belt.  The perception's background removal keeps a further half-diagonal of the part on each
side (``part_fit.in_band``: a 30 mm cube 13 mm off a 40 mm belt's centre line overhangs its edge
by up to 14 mm) and gives each part to the belt whose centre line is nearest its fitted centre.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.measurement import BeltRegionConfig, MeasurementConfig
from ptint_drake.config.pick import PickConfig
from ptint_drake.systems.estimation.imm import AdaptiveTargetEstimator
from ptint_drake.systems.estimation.kalman import TargetKalmanFilter
from ptint_drake.systems.estimation.rotation_estimator import RotationEstimator
from ptint_drake.systems.perception.part_fit import BeltRegion, fold_yaw, yaw_symmetry
from ptint_drake.systems.perception.belt_regions import belt_regions
from ptint_drake.systems.perception.part_pose_estimator import (FIT_NOISE_STD, MakeRgbdPerception,
                                                                PartPoseEstimator, PerceptionConfig)
from ptint_drake.systems.perception.rgbd_camera import (AddRgbdCamera, RgbdCamera, camera_info, camera_pose,
                                                        describe_pose, in_view)
from ptint_drake.systems.perception.track_system import TrackingPartPoseEstimator
from ptint_drake.worlds.pick.part_tracks import catalog, tracker_settings
from ptint_drake.worlds.pick.placement import nominal_parts

# a part is aimed at only after this many accepted fits (``world.PickRun``; fewer: ``pick k: part
# not seen``): one fit gives no velocity, and a grasp aimed at it lands wherever the part is not
# (robust assembly_pick_place_rgbd sample 39: part1 fitted once, at t = 0, grasped 107 mm behind it,
# both attempts empty, the next pick collided); three, so that one bad fit does not set the velocity
MIN_FITS = 3
BELT_MARGIN = 0.006  # m, a perceived belt's extra width on each side of the pick belt
# rad²/s³, the rotation filter's white angular acceleration for a part riding a belt (it does not
# spin: 1e-4 of the default ``rotation_estimator.Q_SPIN``, so that the yaw rate averages the fits
# rather than following their jitter over the blind ~0.7 s before a grasp)
BELT_SPIN_Q = 1.0e-7


def camera_of(measurement: MeasurementConfig, pick: PickConfig):
    """The camera config with the parts' shape and size and the perceived belts (module docstring)."""
    part = pick.parts[0]
    belts = measurement.camera.belts or [
        BeltRegionConfig(center=list(b.center), direction=list(b.direction), length=float(b.length),
                         width=float(b.width) + 2 * BELT_MARGIN) for b in pick.belts]
    return dataclasses.replace(measurement.camera, part_shape=part.shape, part_size=list(part.size),
                               belts=belts)


def part_belts(pick: PickConfig) -> list[int]:
    """Per part, the index of its belt among ``pick.belts`` (= among the perceived belts when
    they are derived; configured ones: the one whose centre line passes nearest the part)."""
    names = [b.name for b in pick.belts]
    return [names.index(p.belt) for p in pick.parts]


def _nearest_belts(regions: list[BeltRegion], pick: PickConfig) -> list[int]:
    """Per part, the configured perceived belt whose centre line passes nearest its nominal start."""
    out = []
    for start, _ in nominal_paths(pick):
        distances = []
        for r in regions:
            u, v = r.frame()
            d = start - r.center
            distances.append(abs(d @ v) + max(abs(d @ u) - 0.5 * r.length, 0.0))
        out.append(int(np.argmin(distances)))
    return out


def nominal_paths(pick: PickConfig) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per part: its nominal centre at t = 0 and its belt's velocity (configuration only)."""
    from ptint_drake.worlds.pick.scene import part_start_pose  # noqa: PLC0415  (scene imports Drake models)

    belts = {b.name: b for b in pick.belts}
    out = []
    for part in nominal_parts(pick.parts):
        belt = belts[part.belt]
        d = np.asarray(belt.direction, float)
        out.append((part_start_pose(part, belt).translation(), belt.speed * d / np.linalg.norm(d)))
    return out


def check_pick_camera(scenario) -> None:
    """ScenarioError (one line) for a camera a pick cannot use: a part not in the camera's view
    at its task's start (nothing to see; its nominal place).  Parts of different shapes and sizes
    are classified against the scenario's catalog (``part_tracks.catalog``)."""
    m, pick = scenario.measurement, scenario.pick
    if m is None or m.sensor != "rgbd" or m.camera is None:
        return
    from ptint_drake.worlds.pick.tasks import pick_plan  # noqa: PLC0415

    plan = pick_plan(pick)
    X_WC, info = camera_pose(m.camera), camera_info(m.camera)
    names = [p.name for p in pick.parts]
    paths = nominal_paths(pick)
    for k, task in enumerate(pick.tasks):
        part = names.index(task.part)
        start, velocity = paths[part]
        t = plan.attempts[k][0].start
        if not in_view(X_WC, info, (start + velocity * t)[None])[0]:
            raise ScenarioError(f"measurement.camera: pick.parts[{part}] ({task.part}) is not in view at "
                                f"t = {t:g} s (its task's start) of the camera at {describe_pose(m.camera)} "
                                f"(nothing to see)")


def AddPickCamera(builder: DiagramBuilder, scene_graph, measurement: MeasurementConfig,
                  pick: PickConfig) -> RgbdCamera:
    """The camera rendering the station's scene graph (module docstring)."""
    return AddRgbdCamera(builder, scene_graph, camera_of(measurement, pick), rate_hz=measurement.rate_hz,
                         seed=measurement.seed)


class EstimatedParts(LeafSystem):
    """Per part k: inputs ``estimate_k`` (9, a position estimator's [x, ẋ, ẍ]) and ``rotation_k``
    (15, a rotation filter's [R, ω, ω̇]); outputs ``part_k_pose`` (9), ``part_k_rotation`` (15)
    and ``seen`` (n) (module docstring).  ``nominal``: per part (centre at t = 0, velocity, yaw)."""

    def __init__(self, nominal: list):
        super().__init__()
        self._nominal = [(np.asarray(p, float), np.asarray(v, float), float(yaw)) for p, v, yaw in nominal]
        n = len(nominal)
        self._estimates = [self.DeclareVectorInputPort(f"estimate_{k}", 9) for k in range(n)]
        self._rotations = [self.DeclareVectorInputPort(f"rotation_{k}", 15) for k in range(n)]
        for k in range(n):
            self.DeclareVectorOutputPort(f"part_{k}_pose", 9, self._pose_calc(k))
            self.DeclareVectorOutputPort(f"part_{k}_rotation", 15, self._rotation_calc(k))
        self.DeclareVectorOutputPort("seen", n, self._seen_calc)

    def _estimate(self, context, k: int):
        """Part k's position estimate, or None before its estimator has a sample (all zero)."""
        value = self._estimates[k].Eval(context)
        return value if value[0] != 0.0 or value[1] != 0.0 or value[2] != 0.0 else None

    def _pose_calc(self, k: int):
        def calc(context, output):
            p, v, _ = self._nominal[k]
            value = self._estimate(context, k)
            if value is not None:  # on its belt: its height and no vertical motion are known
                u = v / max(np.linalg.norm(v), 1e-12)
                out = value.copy()
                out[2], out[3:6], out[6:9] = p[2], (value[3:6] @ u) * u, 0.0
                output.SetFromVector(out)
                return
            output.SetFromVector(np.concatenate([p + v * context.get_time(), v, np.zeros(3)]))
        return calc

    def _rotation_calc(self, k: int):
        def calc(context, output):
            if self._estimate(context, k) is not None:
                output.SetFromVector(self._rotations[k].Eval(context))
                return
            value = np.zeros(15)
            value[0:9] = RotationMatrix.MakeZRotation(self._nominal[k][2]).matrix().ravel()
            output.SetFromVector(value)
        return calc

    def _seen_calc(self, context, output) -> None:
        n = len(self._nominal)
        output.SetFromVector([float(self._estimate(context, k) is not None) for k in range(n)])


@dataclass
class PartEstimates:
    """What ``AddPartEstimates`` added."""

    parts: EstimatedParts
    estimator: PartPoseEstimator
    perception: object  # the perception diagram (input ``depth_image``)
    position_filters: list
    rotation_filters: list
    config: PerceptionConfig = None  # what the perception was built from


def _position_filter(config: MeasurementConfig) -> LeafSystem:
    """The position estimator ``config.estimator`` names (``auto``: the IMM), no pre-run samples."""
    if config.estimator == "auto":
        return AdaptiveTargetEstimator(config=config, prior=[])
    return TargetKalmanFilter(config=config, model=config.estimator.split("_", 1)[1], prior=[])


def AddPartEstimates(builder: DiagramBuilder, depth_image, scenario, fits_elsewhere: bool = False
                     ) -> PartEstimates:
    """The perception, the estimators and ``EstimatedParts`` reading ``depth_image`` (module
    docstring); ``fits_elsewhere``: the fits are made outside the diagram
    (``PerceptionConfig.fits_elsewhere``, ``systems.perception.frame_process``)."""
    m, pick = scenario.measurement, scenario.pick
    camera = camera_of(m, pick)
    belts = belt_regions(camera.belts)
    of = part_belts(pick) if not m.camera.belts else _nearest_belts(belts, pick)
    X_WC, info = camera_pose(camera), camera_info(camera)
    config = PerceptionConfig(info, X_WC, belts, camera.part_shape, list(camera.part_size), of,
                              float(m.rate_hz), float(m.latency), check_above=True,
                              fits_elsewhere=fits_elsewhere, catalog=catalog(pick)[0],
                              tracking=tracker_settings(pick, belts, of, nominal_paths(pick), X_WC, info))
    perception, estimator = MakeRgbdPerception(config, TrackingPartPoseEstimator)
    builder.AddNamedSystem("rgbd_perception", perception)
    builder.Connect(depth_image, perception.get_input_port())
    filter_config = m if m.noise_std else dataclasses.replace(m, noise_std=FIT_NOISE_STD)
    nominal = [(p, v, np.radians(part.yaw_deg)) for (p, v), part in zip(nominal_paths(pick),
                                                                      nominal_parts(pick.parts))]
    parts = builder.AddNamedSystem("estimated_parts", EstimatedParts(nominal))
    positions, rotations = [], []
    for k in range(len(pick.parts)):
        kf = builder.AddNamedSystem(f"part_filter_{k}", _position_filter(filter_config))
        builder.Connect(perception.GetOutputPort(f"measurement_{k}"), kf.get_measurement_input_port())
        builder.Connect(kf.get_target_output_port(), parts.GetInputPort(f"estimate_{k}"))
        rf = builder.AddNamedSystem(f"part_rotation_filter_{k}",
                                    RotationEstimator(config=filter_config, prior=[], q=BELT_SPIN_Q))
        builder.Connect(perception.GetOutputPort(f"measured_rotation_{k}"),
                        rf.get_measured_rotation_input_port())
        builder.Connect(rf.get_target_rotation_output_port(), parts.GetInputPort(f"rotation_{k}"))
        positions.append(kf)
        rotations.append(rf)
    return PartEstimates(parts, estimator, perception, positions, rotations, config)


def estimate_metrics(scenario, picks: list, estimates: dict) -> None:
    """Adds to each pick of a camera run ``seen`` and, at its prescribed grasp, the estimate's
    error against the simulated part (``estimate_error_mm``; ``estimate_error_deg``: yaw folded
    by the part's symmetry, 90° for a square-topped box, 180° for another box, none for a
    cylinder); ``estimates``: per task, the values ``world.PickRun`` recorded at the grasp."""
    if scenario.measurement is None or scenario.measurement.sensor != "rgbd":
        return
    for k, pick in enumerate(picks):
        pick["seen"] = pick.get("retry_refused") != "part not seen"
        e = estimates.get(k)
        if e is None:
            pick["estimate_error_mm"] = pick["estimate_error_deg"] = None
            continue
        part = scenario.pick.parts[pick["part_index"]]
        symmetry = yaw_symmetry(part.shape, part.size)
        R, R_hat = e["true_R"].reshape(3, 3), e["estimate_R"].reshape(3, 3)
        dyaw = np.arctan2(R_hat[1, 0], R_hat[0, 0]) - np.arctan2(R[1, 0], R[0, 0])
        pick["estimate_error_mm"] = float(1e3 * np.linalg.norm(e["estimate"] - e["true"]))
        pick["estimate_error_deg"] = float(abs(np.degrees(fold_yaw(dyaw, symmetry))))
