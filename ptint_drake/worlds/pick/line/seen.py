"""A line seen by the rendered RGB-D camera (issue 44, ``measurement.sensor: rgbd`` on a line): the
perception of many undeclared parts and what the line's controller side reads of it.

The perception (``AddLineCamera``) is the task-list pick's (``systems.perception``: Drake's
``RgbdSensor`` on ``RenderEngineVtk`` in the station, the depth image to a point cloud, the
belts' part bands, ``catalog_fit`` classifying every cluster against the line's catalog by its
measured top face and height, boxes and cylinders mixed) with ``track_system``'s tracker told of
*no* part: ``tracks.TrackerSettings`` with the catalog's yaw symmetries (a cube's 90°, another
box's 180°, a cylinder none), each belt's declared velocity as a new track's prior, the camera's
view (a track whose predicted centre leaves it ends) and no declared objects — a part released
upstream becomes a track when it enters the view and is fitted ``tracks.CONFIRM`` times; gating
and ``scipy.optimize.linear_sum_assignment`` keep one track per part; a track coasts on its own
constant-velocity Kalman filter through the arm's occlusion (``tracks.MAX_COAST``).

``LineSeenParts`` (controller side: its only input is the tracker's state) keeps, per live track,
the running mean of its fitted yaws (a part riding a belt does not turn; each fit is unwrapped by
the class's symmetry) beside the tracker's own filter, and gives ``PickTargets`` per pool slot k
the estimate of the track a task aims slot k at (``aim``: set by the driver's decision before the
diagram it rebuilds is run): the filter's centre moved along its belt at the filter's velocity
along it (the conveyor's constraint: the height is the belt's top plus half the class's height,
no vertical motion), turned by the mean yaw.  The rows are copied at every frame's time from the
tracker as of the previous frame (one period behind: the frame's processing), so a track that
ends (it left the view, or coasted too long) keeps its last row, extrapolated; a slot aimed since
the last frame (a task decided between frames) reads its track from the tracker directly until
then.  A slot no track is aimed at reads zeros.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from pydrake.math import RotationMatrix
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from ptint_drake.config.measurement import BeltRegionConfig
from ptint_drake.config.part_shape import part_height
from ptint_drake.systems.perception.belt_regions import belt_regions
from ptint_drake.systems.perception.part_fit import yaw_symmetry
from ptint_drake.systems.perception.part_pose_estimator import MakeRgbdPerception, PerceptionConfig
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose
from ptint_drake.systems.perception.track_system import TrackingPartPoseEstimator
from ptint_drake.systems.perception.tracks import CONFIRMED, MAX_TRACKS, Tracker, TrackerSettings
from ptint_drake.worlds.pick.part_tracks import CameraView

BELT_MARGIN = 0.006  # m, a perceived belt's extra width on each side of the pick belt (``pick.camera``)
YAWS = 4  # per live track: id, its last fit's time, fits averaged, mean yaw
SLOT = 9  # per pool slot: track id, time, x, y, vx, vy, belt, yaw, class


def line_catalog(line) -> list:
    """The line's kinds as the perception's catalog: (shape, size) each, in ``line.catalog`` order."""
    return [(kind.shape, [float(v) for v in kind.size]) for kind in line.catalog]


def line_perception(scenario) -> PerceptionConfig:
    """The perception of a line's camera (module docstring): every ``pick.belts`` entry perceived
    ``BELT_MARGIN`` wider each side, the catalog, no declared part."""
    m, pick = scenario.measurement, scenario.pick
    regions = belt_regions([BeltRegionConfig(center=list(b.center), direction=list(b.direction),
                                             length=float(b.length), width=float(b.width) + 2 * BELT_MARGIN)
                            for b in pick.belts])
    kinds = line_catalog(pick.line)
    X_WC, info = camera_pose(m.camera), camera_info(m.camera)
    velocities = [b.speed * np.asarray(b.direction, float) / np.linalg.norm(b.direction) for b in pick.belts]
    settings = TrackerSettings([yaw_symmetry(shape, size) for shape, size in kinds], velocities,
                               visible=CameraView(X_WC, info))
    return PerceptionConfig(info, X_WC, regions, kinds[0][0], kinds[0][1], [], float(m.rate_hz),
                            float(m.latency), check_above=True, catalog=kinds, tracking=settings)


class LineSeenParts(LeafSystem):
    """Input ``tracker_state`` (``tracks.Tracker.state_vector``); outputs ``part_k_pose`` (9) and
    ``part_k_rotation`` (15) per pool slot k (module docstring); ``config``: the line's perception
    (its classes give the centres' heights over the belt, its belts their tops and directions),
    ``slots``: the pool's size."""

    def __init__(self, config: PerceptionConfig, slots: int):
        super().__init__()
        self._settings, self._n = config.tracking, slots
        self._heights = [0.5 * part_height(shape, size) for shape, size in config.kinds()]
        self._belts = [(float(b.center[2]), np.asarray(b.direction, float) / np.linalg.norm(b.direction))
                       for b in config.belts]
        self._aims = np.zeros(slots)  # per slot: the track id a task aims it at (0: none)
        size = Tracker(self._settings).size()
        self._tracker_in = self.DeclareVectorInputPort("tracker_state", size)
        self._yaws = self.DeclareDiscreteState(np.zeros(MAX_TRACKS * YAWS))
        self._rows = self.DeclareDiscreteState(np.zeros(slots * SLOT))
        self.DeclarePeriodicUnrestrictedUpdateEvent(1.0 / config.rate_hz, 0.0, self._update)
        reads = {self.xd_ticket(), self.all_input_ports_ticket()}
        for k in range(slots):
            self.DeclareVectorOutputPort(f"part_{k}_pose", 9, self._pose_calc(k),
                                         prerequisites_of_calc=reads | {self.time_ticket()})
            self.DeclareVectorOutputPort(f"part_{k}_rotation", 15, self._rotation_calc(k),
                                         prerequisites_of_calc=reads)

    def aim(self, aims: dict) -> None:
        """{slot: track id}: what each task's slot reads (set before a context of this system is made)."""
        self._aims = np.zeros(self._n)
        for k, track in aims.items():
            self._aims[k] = track

    def tracker(self, context) -> Tracker:
        """The tracker as this system reads it now."""
        return Tracker(self._settings).load(self._tracker_in.Eval(context))

    def mean_yaws(self, context) -> dict:
        """{track id: the mean of its fitted yaws (rad)} of the live tracks."""
        rows = context.get_discrete_state(self._yaws).value().reshape(MAX_TRACKS, YAWS)
        return {int(r[0]): float(r[3]) for r in rows if r[0] > 0}

    def confirmed(self, context) -> list:
        """[(tracks.Track, mean yaw)] of the confirmed tracks now."""
        yaws = self.mean_yaws(context)
        live = self.tracker(context).tracks
        return [(tr, yaws.get(tr.id, tr.yaw)) for tr in live if tr.status == CONFIRMED]

    def _update(self, context, state) -> None:
        tracker = self.tracker(context)
        old = {int(r[0]): r for r in context.get_discrete_state(self._yaws).value().reshape(MAX_TRACKS, YAWS)
               if r[0] > 0}
        yaws = np.zeros((MAX_TRACKS, YAWS))
        for row, tr in zip(yaws, tracker.tracks):
            row[:] = old.get(tr.id, [tr.id, -1.0, 0.0, tr.yaw])
            if tr.seen > row[1] + 1e-9:  # a new fit: its yaw, unwrapped by the class, into the mean
                step = self._settings.symmetries[tr.kind]
                fit = row[3] + ((tr.yaw - row[3] + 0.5 * step) % step - 0.5 * step) if step > 0.0 else 0.0
                row[1:4] = [tr.seen, row[2] + 1.0, row[3] + (fit - row[3]) / (row[2] + 1.0)]
        rows = context.get_discrete_state(self._rows).value().reshape(self._n, SLOT).copy()
        live = {tr.id: tr for tr in tracker.tracks}
        mean = {int(r[0]): r[3] for r in yaws if r[0] > 0}
        for k in np.flatnonzero(self._aims):
            tr = live.get(int(self._aims[k]))
            if tr is not None:
                rows[k] = [tr.id, tr.t, *tr.x, tr.belt, mean[tr.id], tr.kind]
        state.get_mutable_discrete_state(self._yaws).SetFromVector(yaws.ravel())
        state.get_mutable_discrete_state(self._rows).SetFromVector(rows.ravel())

    def _row(self, context, k: int):
        """Slot k's row: as copied at the last frame, or — aimed since (a new task, before the next
        frame) — the aimed track as the tracker has it now; None: nothing aimed, or its track gone."""
        row = context.get_discrete_state(self._rows).value()[k * SLOT:(k + 1) * SLOT]
        if self._aims[k] == 0 or (row[0] > 0 and row[0] == self._aims[k]):
            return row if self._aims[k] else None
        tr = next((tr for tr in self.tracker(context).tracks if tr.id == self._aims[k]), None)
        if tr is None:
            return None
        return np.array([tr.id, tr.t, *tr.x, tr.belt, self.mean_yaws(context).get(tr.id, tr.yaw), tr.kind])

    def _pose_calc(self, k: int):
        def calc(context, output):
            row = self._row(context, k)
            if row is None:
                output.SetFromVector(np.zeros(9))
                return
            top, u = self._belts[int(row[6])]
            v = float(row[4:6] @ u[0:2]) * u
            p = np.array([row[2], row[3], top + self._heights[int(row[8])]])
            p += v * (context.get_time() - row[1])
            output.SetFromVector(np.concatenate([p, v, np.zeros(3)]))
        return calc

    def _rotation_calc(self, k: int):
        def calc(context, output):
            row = self._row(context, k)
            value = np.zeros(15)
            yaw = 0.0 if row is None else float(row[7])
            value[0:9] = RotationMatrix.MakeZRotation(yaw).matrix().ravel()
            output.SetFromVector(value)
        return calc


@dataclasses.dataclass
class LineCamera:
    """What ``AddLineCamera`` added: the perception diagram, its tracker system and the slots' view."""

    perception: object
    estimator: TrackingPartPoseEstimator
    parts: LineSeenParts
    config: PerceptionConfig


def AddLineCamera(builder: DiagramBuilder, depth_image, scenario) -> LineCamera:
    """The line's perception reading ``depth_image`` and ``LineSeenParts`` over the pool's slots
    (``scenario``: the line's expanded copy; module docstring)."""
    config = line_perception(scenario)
    perception, estimator = MakeRgbdPerception(config, TrackingPartPoseEstimator)
    builder.AddNamedSystem("rgbd_perception", perception)
    builder.Connect(depth_image, perception.get_input_port())
    parts = builder.AddNamedSystem("line_seen_parts", LineSeenParts(config, len(scenario.pick.parts)))
    builder.Connect(perception.GetOutputPort("tracker_state"), parts.get_input_port())
    return LineCamera(perception, estimator, parts, config)
