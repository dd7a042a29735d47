"""``PartPoseEstimator`` — per frame, the parts' poses fitted to the camera's point cloud, in
the shape of the pose camera's samples; ``MakeRgbdPerception`` — the pipeline from a depth
image to those samples as one diagram whose only input is the image.

Pipeline per frame (period 1 / ``rate_hz``, frame k at t_k = k / rate): Drake's
``DepthImageToPointCloud`` (the configured camera pose X_WC on its ``camera_pose`` port, so the
cloud is in the world frame; missing pixels become NaN), ``PointCloud.Crop`` to the box around
the configured belts, ``PointCloud.VoxelizedDownSample`` (``VOXEL``), then ``part_fit.fit_parts``
(background removal from the belts, clustering, the shape fit, quality).

Data association (no truth): object i is looked for on belt ``object_belts[i]``; among the
good fits there it takes the one nearest its last accepted position (within ``GATE``), or —
never seen yet — the one farthest downstream (the pick world: by tracks, ``track_system``).
Its yaw is unwrapped: the fit's yaw is known only up to the part's symmetry, and the sample
reports the symmetric yaw nearest the last one.
A frame where object i has no good fit (not in view, occluded, a poor fit) is a dropout for it:
its output keeps the last sample (same stamp), as the pose camera's does.

Timing (the pose camera's, ``systems.perception.camera``): the sample taken at t_k becomes visible at
t_k + latency (latency > 0: the frame is processed after it is taken).  The discrete state is a
delay buffer of the last N frames, newest first, each [stamp, x, y, z, valid, R (9)] per object,
and the association's memory; an abstract state holds the newest frame's fits (``fits``).

Outputs: ``measurement_i`` (5: [stamp, x, y, z, valid]) and ``measured_rotation_i`` (11:
[stamp, R row-major, valid]) per object — the ports ``kalman.AddCameraEstimators`` and
``rotation_estimator.AddRotationEstimators`` read — ``quality_i`` (7: [stamp, inliers, residual
(m), the position covariance's diagonal (m²), valid]) of the same sample, and ``fits`` (list of
``PartFit`` of the newest processed frame, failed fits included, with their quality and
covariance: what a pick world's part-pose source would read), and ``fit_counts`` (n: per
object, the fits accepted so far, counted when its frame is processed).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.perception import BaseField, DepthImageToPointCloud, PointCloud
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem, OutputPort
from pydrake.systems.primitives import ConstantValueSource
from pydrake.systems.sensors import CameraInfo, PixelType

from ptint_drake.config.part_shape import part_height
from ptint_drake.systems.perception.belt_regions import perception_belts
from ptint_drake.systems.perception.catalog_fit import catalog_points, fit_catalog
from ptint_drake.systems.perception.part_fit import BELT_BAND, TOP_BAND, fit_parts, reach
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose, cloud_camera_info

# m: the fits' noise the estimators assume when measurement.noise_std is 0 (the default): the
# position error of a 30 mm cube's fit at 0.5 m is 0.2-0.7 mm (tests/unit/test_perception.py)
FIT_NOISE_STD = 0.0005
VOXEL = 0.0015  # m, the voxel grid of the cloud (≈ 2 pixel footprints at 0.5 m)
GATE = 0.05  # m, farthest a part moves between two accepted fits
OCCLUDER_RADIUS = 0.05  # m, horizontal, around a fit's centre (half a 30 mm cube's diagonal + the
# 28° tilt's shift of an occluder 40 mm above it)
OCCLUDER_GAP = 0.008  # m, above the fitted top face
OCCLUDER_HEIGHT = 0.25  # m, above the fitted top face
TIME_TOL = 1.0e-9
# per object and slot: [stamp, x, y, z, valid, R (9), inliers, residual, covariance diagonal (3)]
_WIDTH = 19
QUALITY_SIZE = 7  # [stamp, inliers, residual (m), var x, var y, var z (m²), valid]


@dataclass
class PerceptionConfig:
    """What the perception knows: the camera (intrinsics, pose), the belts, the parts' shape,
    which belt each tracked object rides, and the frame timing."""

    info: CameraInfo
    X_WC: RigidTransform
    belts: list
    shape: str
    size: list
    object_belts: list
    rate_hz: float
    latency: float
    # a good fit with anything in the cloud above it (within OCCLUDER_RADIUS of its centre, from
    # OCCLUDER_GAP above its top to OCCLUDER_HEIGHT): a dropout (e.g. the gripper coming down over
    # it hides part of its top face before the fit fails the completeness check)
    check_above: bool = False
    # the fits are made outside the diagram (``frame_process.FrameProcess``: a control loop that
    # must not wait for them) and written by ``write_frame``; the frame's event only marks its time
    fits_elsewhere: bool = False
    # the kinds of part, (shape, size) each (issue 44: ``catalog_fit``); empty: (shape, size) alone
    catalog: list = field(default_factory=list)
    tracking: object = None  # ``tracks.TrackerSettings`` of ``track_system.TrackingPartPoseEstimator``

    def kinds(self) -> list:
        """The catalog, or the one known shape."""
        return list(self.catalog) or [(self.shape, list(self.size))]


class PartPoseEstimator(LeafSystem):
    """Input ``point_cloud`` (world frame); outputs of the module docstring."""

    def __init__(self, config: PerceptionConfig):
        super().__init__()
        if not config.latency > TIME_TOL:
            raise ValueError("measurement.latency: an rgbd camera needs a latency > 0 (its frame is "
                             "processed after it is taken; e.g. 0.033 at 30 Hz)")
        self._c = config
        self._n = len(config.object_belts)
        self._period = 1.0 / config.rate_hz
        self._slots = math.ceil(config.latency * config.rate_hz - TIME_TOL) + 2
        self._lo, self._hi = self._crop_box()
        distance = min(float(np.linalg.norm(np.asarray(b.center) - config.X_WC.translation()))
                       for b in config.belts) if config.belts else 0.5
        self._footprint = distance / config.info.focal_y()
        self._cloud_in = self.DeclareAbstractInputPort("point_cloud", AbstractValue.Make(PointCloud()))
        self._buffer = self.DeclareDiscreteState(np.zeros(self._slots * self._n * _WIDTH))
        # per object: [fits accepted so far, x, y, z, yaw] of the last accepted fit
        self._memory = self.DeclareDiscreteState(np.zeros(self._n * 5))
        self._fits = self.DeclareAbstractState(AbstractValue.Make([]))
        self._timing = self.DeclareAbstractState(AbstractValue.Make({}))
        if config.fits_elsewhere:
            self.DeclarePeriodicPublishEvent(self._period, 0.0, lambda context: None)
        else:
            self.DeclarePeriodicUnrestrictedUpdateEvent(self._period, 0.0, self._update)
        self.DeclarePeriodicPublishEvent(self._period, config.latency, lambda context: None)
        prerequisites = {self.time_ticket(), self.xd_ticket()}
        self.measurement_ports, self.rotation_ports = [], []
        for i in range(self._n):
            self.measurement_ports.append(self.DeclareVectorOutputPort(
                f"measurement_{i}", 5, self._measurement_calc(i), prerequisites_of_calc=prerequisites))
            self.rotation_ports.append(self.DeclareVectorOutputPort(
                f"measured_rotation_{i}", 11, self._rotation_calc(i), prerequisites_of_calc=prerequisites))
            self.DeclareVectorOutputPort(f"quality_{i}", QUALITY_SIZE, self._quality_calc(i),
                                         prerequisites_of_calc=prerequisites)
        self.DeclareVectorOutputPort("fit_counts", self._n, self._fit_counts_calc,
                                     prerequisites_of_calc={self.xd_ticket()})
        self.DeclareAbstractOutputPort("fits", lambda: AbstractValue.Make([]), self._fits_calc,
                                       prerequisites_of_calc={self.abstract_state_ticket(self._fits)})

    def _fit_counts_calc(self, context, output) -> None:
        output.SetFromVector(context.get_discrete_state(self._memory).value().reshape(self._n, 5)[:, 0])

    def _fits_calc(self, context, output) -> None:
        output.set_value(list(context.get_abstract_state(self._fits).get_value()))

    def _crop_box(self) -> tuple[np.ndarray, np.ndarray]:
        """The box around the belts' part bands (``part_fit.in_band``): their rectangles widened by
        the part's reach, from ``BELT_BAND`` above the belts (the belt surface is most of the
        cloud there: the cheap test drops it) to the part's height + ``TOP_BAND``."""
        if not self._c.belts:
            return np.zeros(3), np.zeros(3)
        corners = []
        r = max(reach(shape, size) for shape, size in self._c.kinds())
        top = max(part_height(shape, size) for shape, size in self._c.kinds()) + TOP_BAND
        for b in self._c.belts:
            u, v = b.frame()
            for su in (-1, 1):
                for sv in (-1, 1):
                    for h in (BELT_BAND, top):
                        corners.append(np.asarray(b.center, float) + su * (0.5 * b.length + r) * u
                                       + sv * (0.5 * b.width + r) * v + [0.0, 0.0, h])
        corners = np.array(corners)
        return corners.min(axis=0), corners.max(axis=0)

    def frame_points(self, cloud: PointCloud) -> np.ndarray:
        """The cloud cropped to the belts' part bands (the box around them, then each belt's
        rectangle and height band: ``part_fit.belt_points``) and downsampled (N × 3)."""
        xyz = cloud.xyzs()
        with np.errstate(invalid="ignore"):  # the height first: it leaves few points (NaN: out)
            z = xyz[2]
            boxed = xyz[:, np.flatnonzero((z >= self._lo[2]) & (z <= self._hi[2]))].T
            boxed = boxed[np.all((boxed >= self._lo) & (boxed <= self._hi), axis=1)]
        points = catalog_points(boxed, self._c.belts, self._c.kinds())
        if len(points) == 0:
            return points
        kept = PointCloud(len(points))
        kept.mutable_xyzs()[:] = points.T
        return kept.VoxelizedDownSample(VOXEL).xyzs().T

    def fit_frame(self, cloud: PointCloud) -> list:
        options = {"footprint": self._footprint, "spacing": max(VOXEL, 1.2 * self._footprint)}
        if len(self._c.kinds()) > 1:
            fits = fit_catalog(self.frame_points(cloud), self._c.belts, self._c.kinds(), **options)
        else:
            fits = fit_parts(self.frame_points(cloud), self._c.belts, self._c.shape, self._c.size, **options)
        if self._c.check_above and any(f.ok for f in fits):
            self._mark_covered(cloud, fits)
        return fits

    def _mark_covered(self, cloud: PointCloud, fits: list) -> None:
        """``check_above``: a good fit with cloud points above it is a dropout (not the points of
        another good fit's part: a taller neighbour of another kind is not an occluder)."""
        xyz, kinds = cloud.xyzs(), self._c.kinds()
        tops = [0.5 * part_height(*kinds[f.kind]) for f in fits]
        lo = min(f.position[2] + top for f, top in zip(fits, tops) if f.ok) + OCCLUDER_GAP
        with np.errstate(invalid="ignore"):
            high = xyz[:, np.flatnonzero((xyz[2] > lo) & (xyz[2] < lo + OCCLUDER_HEIGHT))].T
        for g, top in zip(fits, tops):
            if g.ok and len(high) and len(kinds) > 1:
                high = high[(np.hypot(*(high[:, 0:2] - g.position[0:2]).T) > reach(*kinds[g.kind]) + 0.003)
                            | (high[:, 2] > g.position[2] + top + TOP_BAND)]
        for f, top in zip(fits, tops):
            if not f.ok or len(high) == 0:
                continue
            above = high[high[:, 2] > f.position[2] + top + OCCLUDER_GAP]
            near = np.hypot(above[:, 0] - f.position[0], above[:, 1] - f.position[1]) < OCCLUDER_RADIUS
            if np.count_nonzero(near) >= 3:
                f.ok, f.reason = False, f"{np.count_nonzero(near)} points above it (occluded?)"

    def _associate(self, fits: list, memory: np.ndarray) -> list:
        """Per object: its fit (or None) and the new memory row."""
        chosen = []
        for i, belt in enumerate(self._c.object_belts):
            candidates = [f for f in fits if f.ok and f.belt == belt]
            seen, last = memory[i, 0] > 0.5, memory[i, 1:4]
            fit = None
            if candidates and seen:
                fit = min(candidates, key=lambda f: np.linalg.norm(f.position - last))
                if np.linalg.norm(fit.position - last) > GATE:
                    fit = None
            elif candidates:
                u, _ = self._c.belts[belt].frame()
                fit = max(candidates, key=lambda f: f.position @ u)
            chosen.append(fit)
        return chosen

    def _choose(self, context, state, t: float, fits: list, memory: np.ndarray) -> list:
        """Per object: its fit of the frame taken at ``t``, or None (``track_system`` chooses by
        tracks)."""
        return self._associate(fits, memory)

    def _update(self, context, state) -> None:
        t = context.get_time()
        start = time.perf_counter()
        cloud = self._cloud_in.Eval(context)
        rendered = time.perf_counter()
        fits = self.fit_frame(cloud)
        timing = {"cloud_s": rendered - start, "fit_s": time.perf_counter() - rendered}
        self._write(context, state, t, fits, timing)

    def write_frame(self, context, t: float, fits: list, timing: dict) -> None:
        """With ``fits_elsewhere``: the fits of the frame taken at ``t`` into ``context`` (this
        system's), as this system's own update at ``t`` writes them."""
        self._write(context, context, t, fits, timing)

    def _write(self, context, state, t: float, fits: list, timing: dict) -> None:
        """The frame at ``t``'s samples from ``fits`` into ``state`` (a State, or the context
        itself), associated with the memory in ``context``."""
        memory = context.get_discrete_state(self._memory).value().reshape(self._n, 5).copy()
        chosen = self._choose(context, state, t, fits, memory)
        old = context.get_discrete_state(self._buffer).value()
        slot = old[:self._n * _WIDTH].reshape(self._n, _WIDTH).copy()  # a dropout holds the last sample
        for i, fit in enumerate(chosen):
            if fit is None:
                continue
            yaw = fit.yaw
            if memory[i, 0] > 0.5 and fit.symmetry > 0.0:
                step = fit.symmetry
                yaw = memory[i, 4] + ((fit.yaw - memory[i, 4] + 0.5 * step) % step - 0.5 * step)
            memory[i] = [memory[i, 0] + 1.0, *fit.position, yaw]  # (column 0: the fits accepted)
            c, s = math.cos(yaw), math.sin(yaw)
            R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
            slot[i] = [t, *fit.position, 1.0, *R.ravel(), fit.inliers, fit.residual,
                       *np.diag(fit.covariance)]
        new = np.concatenate([slot.ravel(), old[:-self._n * _WIDTH]])
        state.get_mutable_discrete_state(self._buffer).SetFromVector(new)
        state.get_mutable_discrete_state(self._memory).SetFromVector(memory.ravel())
        state.get_mutable_abstract_state(self._fits).set_value(fits)
        state.get_mutable_abstract_state(self._timing).set_value({"t": t} | timing)

    def _visible(self, context, i: int) -> np.ndarray:
        t = context.get_time()
        slots = context.get_discrete_state(self._buffer).value().reshape(self._slots, self._n, _WIDTH)
        for slot in slots:
            row = slot[i]
            if row[4] > 0.5 and row[0] + self._c.latency <= t + TIME_TOL:
                return row
        return np.zeros(_WIDTH)

    def _measurement_calc(self, i: int):
        return lambda context, output: output.SetFromVector(self._visible(context, i)[0:5])

    def _rotation_calc(self, i: int):
        def calc(context, output):
            row = self._visible(context, i)
            output.SetFromVector(np.concatenate([row[0:1], row[5:14], row[4:5]]))
        return calc

    def _quality_calc(self, i: int):
        def calc(context, output):
            row = self._visible(context, i)
            output.SetFromVector(np.concatenate([row[0:1], row[14:19], row[4:5]]))
        return calc

    def timing(self, context) -> dict:
        """{t, cloud_s, fit_s} of the newest frame (seconds of wall time: the render and the
        cloud — pulled by the cloud's evaluation — and the fit)."""
        return dict(context.get_abstract_state(self._timing).get_value())


def MakeRgbdPerception(config: PerceptionConfig, estimator_type=None) -> tuple[Diagram, PartPoseEstimator]:
    """The pipeline as one diagram: input ``depth_image`` (ImageDepth32F), outputs those of the
    ``PartPoseEstimator`` (or ``estimator_type``, e.g. ``track_system``'s: its ``tracks`` too)."""
    builder = DiagramBuilder()
    cloud = builder.AddNamedSystem("depth_to_cloud", DepthImageToPointCloud(  # (RENDER_PIXEL_SHIFT)
        cloud_camera_info(config.info), PixelType.kDepth32F, 1.0, BaseField.kXYZs))
    pose = builder.AddNamedSystem("camera_pose", ConstantValueSource(AbstractValue.Make(config.X_WC)))
    builder.Connect(pose.get_output_port(), cloud.camera_pose_input_port())
    estimator = builder.AddNamedSystem("part_poses", (estimator_type or PartPoseEstimator)(config))
    builder.Connect(cloud.point_cloud_output_port(), estimator.GetInputPort("point_cloud"))
    builder.ExportInput(cloud.depth_image_input_port(), "depth_image")
    for i in range(len(config.object_belts)):
        builder.ExportOutput(estimator.GetOutputPort(f"measurement_{i}"), f"measurement_{i}")
        builder.ExportOutput(estimator.GetOutputPort(f"measured_rotation_{i}"), f"measured_rotation_{i}")
        builder.ExportOutput(estimator.GetOutputPort(f"quality_{i}"), f"quality_{i}")
    builder.ExportOutput(estimator.GetOutputPort("fits"), "fits")
    if estimator.HasOutputPort("tracks"):
        builder.ExportOutput(estimator.GetOutputPort("tracks"), "tracks")
        builder.ExportOutput(estimator.GetOutputPort("tracker_state"), "tracker_state")
    diagram = builder.Build()
    diagram.set_name("rgbd_perception")
    return diagram, estimator


@dataclass
class SeenObject:
    """Object i as the estimators see it through the perception (the ``Camera`` interface that
    ``kalman.AddCameraEstimators`` and ``rotation_estimator.AddRotationEstimators`` read): its
    measurement ports; no pre-run samples (the camera starts seeing at t = 0)."""

    measurement: OutputPort
    rotation: OutputPort
    measures_rotation: bool = True

    def get_measurement_output_port(self) -> OutputPort:
        return self.measurement

    def get_measured_rotation_output_port(self) -> OutputPort:
        return self.rotation

    def pre_run_samples(self, visible_by: float = 0.0) -> list:
        return []

    def pre_run_rotations(self, visible_by: float = 0.0) -> list:
        return []


def AddRgbdPerception(builder: DiagramBuilder, depth_image: OutputPort, measurement, targets,
                      duration: float) -> tuple[list[SeenObject], PartPoseEstimator]:
    """The perception of ``measurement`` (sensor rgbd) reading ``depth_image``; one
    ``SeenObject`` per object of ``targets`` (whose motions give only the belts when none are
    configured: ``perception_belts``)."""
    c = measurement.camera
    belts, of = perception_belts(measurement, targets, duration)
    config = PerceptionConfig(camera_info(c), camera_pose(c), belts, c.part_shape, list(c.part_size), of,
                              float(measurement.rate_hz), float(measurement.latency))
    diagram, estimator = MakeRgbdPerception(config)
    builder.AddNamedSystem("rgbd_perception", diagram)
    builder.Connect(depth_image, diagram.get_input_port())
    seen = [SeenObject(diagram.GetOutputPort(f"measurement_{i}"),
                       diagram.GetOutputPort(f"measured_rotation_{i}")) for i in range(len(of))]
    return seen, estimator
