"""What the controller side of a line reads at a stop (``driver``): the tracks in the part
tracker's report, each belt's known speed, each track's reach window — never the pool's truth.

- **the view**: a report is a track when it lies on a belt (within its width, resting on it) from
  ``VIEW_BEFORE`` upstream of the release point on; parked parts (under the floor), parts in the
  hand and in the tray are none.  Its kind is the catalog kind of the reported part's declared
  shape and size (the pose sensor's object model, from the cell both sides build from);
- **with the rgbd camera** (``measurement``, ``seen``) the tracks are the perception's confirmed
  tracks instead — ids, kinds classified by the measured size and shape, positions and velocities
  from each track's own filter, yaws the mean of its fits — never the pool; a task's slot reads
  the track it is aimed at (``aim``), and the plan's model holds each tracked part at the slot a
  task aims at it, or at a slot no task uses (``slots_of``).  A track is reported once it is
  classified: ``CLASSIFIED_FITS`` fits, ``CLASS_SHARE`` of them of one class (measured,
  line_two_belts_rgbd seed 0: a cube's first 7 fits at the view's upstream edge, its top face cut
  by the image's border, were classed as discs — its slot chosen on them was a disc's);
- **the known speed** of a belt: its encoder's reading (the drive joint's rate) where the line
  declares ``encoder: true``, else the declared ``speed`` — a speed step is unknown then, until
  a track's drift shows it: the speed the sensor reports for that track is learned for the belt
  (``learned``, set by ``driver``);
- **the reach window** of a track (``window``): along its belt, at its lateral offset and the height
  the tool grips it at (its centre's, or above it: ``config.grip_height``),
  the longest stretch where a top-down grasp and the lift above it are reachable (Drake's IK,
  ``robot.reachability.inverse_kinematics(down=True)``, every ``WINDOW_STEP``), cached per
  (belt, lateral, height) — for the process (``_WINDOWS``): a window depends on the arm's
  kinematics, its start posture and the belt's place only, so the samples of a study (each a new
  run in the same worker) scan each once (measured, line_assembly: 0.67 s of a 10 s sample, 965
  IK solves, for its three belts).
"""

from __future__ import annotations

import math

import numpy as np

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.config.part_shape import part_height
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.perception.part_fit import reach
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.config import grip_height
from ptint_drake.worlds.pick.scene import belt_frame, hand_size

VIEW_BEFORE = 0.05  # m, upstream of the release point: where the view begins
WINDOW_STEP = 0.01  # m, of the reach window's scan
KEY_STEP = 0.005  # m: windows are scanned at the lateral offset and height rounded to this
# (robot model, end effector, start posture, the belt's centre, direction and length, the rounded
# lateral offset and height, the lift's height) → the window: the scans of this process
_WINDOWS: dict = {}
CLASSIFIED_FITS = 15  # fits of a camera track before it is reported (0.5 s at 30 Hz)
CLASS_SHARE = 0.75  # of its fits of its class


class LineView:
    """The controller side's reading of a line (module docstring); ``bind`` a built diagram first."""

    def __init__(self, scenario):
        self.scenario, self.line = scenario, scenario.pick.line
        self._windows: dict = {}
        self.built = None
        m = scenario.measurement
        self.camera = m is not None and m.sensor == "rgbd"  # the tracks are the camera's (``seen``)
        self.aims: dict = {}  # with the camera: pool slot → the track id a task aims it at
        # belt → the speed learned from its tracks after a drift (no encoder: ``driver``)
        self.learned: dict = {}

    def bind(self, built) -> None:
        self.built = built
        self._arm = built.arm
        self._frame = built.arm.GetFrameByName(self.scenario.robot.end_effector)
        if self.camera:
            built.line_camera.parts.aim(self.aims)

    def aim(self, slot: int, track: int) -> None:
        """With the camera: the task of pool slot ``slot`` aims at track ``track`` (from the next build)."""
        self.aims[slot] = track

    def slots_of(self, ids) -> dict:
        """{track id: the pool slot the plan's model holds it at}: the sensor's own identities; with
        the camera the slot a task aims at it, else the free slots from the last one down."""
        if not self.camera:
            return {i: i for i in ids}
        bound = {track: slot for slot, track in self.aims.items()}
        free = [k for k in reversed(range(len(self.scenario.pick.parts))) if k not in self.aims]
        out = {}
        for i in sorted(ids):
            if i in bound:
                out[i] = bound[i]
            elif free:
                out[i] = free.pop(0)
        return out

    def _known_speed(self, context, belt) -> float:
        encoder = {b.name: b.encoder for b in self.line.belts}.get(belt.name, False)
        if not encoder:
            return self.learned.get(belt.name, belt.speed)
        station = self.built.station
        joint = station.belts[[b.name for b in station.config.belts].index(belt.name)]
        return float(joint.get_translation_rate(station.plant.GetMyContextFromRoot(context)))

    def _kind(self, part) -> str:
        for c in self.line.catalog:
            if c.shape == part.shape and np.allclose(c.size, part.size):
                return c.name
        return ""

    def tracks(self, context, t: float) -> list[Track]:
        """The tracks (module docstring: the view) in the tracker's report now."""
        if self.camera:
            return self._camera_tracks(context, t)
        config, source = self.built.station.config, self.built.part_system()
        sc = source.GetMyContextFromRoot(context)
        belts = {b.name: b for b in config.belts}
        view = {a.belt: a.release - VIEW_BEFORE for a in self.line.arrivals}
        out = []
        for k, part in enumerate(config.parts):
            pose = source.GetOutputPort(f"part_{k}_pose").Eval(sc)
            R = source.GetOutputPort(f"part_{k}_rotation").Eval(sc)[0:9].reshape(3, 3)
            belt = belts[part.belt]
            local = belt_frame(belt).inverse().multiply(pose[0:3])
            height = part_height(part.shape, part.size)
            if not (abs(local[1]) <= belt.width / 2 and abs(local[2] - height / 2) < 0.01
                    and view[belt.name] <= local[0] <= belt.length / 2):
                continue
            out.append(Track(k, self._kind(part), belt.name, tuple(pose[0:3]), float(local[0]),
                             tuple(belt.direction), self._known_speed(context, belt), tuple(R[:, 0]),
                             float(part.size[0]), reach(part.shape, part.size),
                             float(np.dot(pose[3:6], belt.direction))))
        return out

    def _camera_tracks(self, context, t: float) -> list[Track]:
        """The perception's confirmed tracks on the line's belts, predicted to ``t`` along their belt."""
        seen = self.built.line_camera.parts
        belts, kinds = self.scenario.pick.belts, self.line.catalog
        line_belts = {b.name for b in self.line.belts}
        out = []
        for tr, yaw in seen.confirmed(seen.GetMyContextFromRoot(context)):
            if tr.hits < CLASSIFIED_FITS or tr.votes.max() < CLASS_SHARE * tr.votes.sum():
                continue
            belt, kind = belts[tr.belt], kinds[tr.kind]
            u = np.asarray(belt.direction, float) / np.linalg.norm(belt.direction)
            along = float(tr.x[2:4] @ u[0:2])
            height = part_height(kind.shape, kind.size)
            p = np.array([tr.x[0], tr.x[1], belt.center[2] + height / 2]) + along * u * (t - tr.t)
            s = float(belt_frame(belt).inverse().multiply(p)[0])
            if belt.name not in line_belts or abs(s) > belt.length / 2:
                continue
            speed = self._known_speed(context, belt)
            axis = (math.cos(yaw), math.sin(yaw), 0.0)
            out.append(Track(tr.id, kind.name, belt.name, tuple(p), s, tuple(u), speed, axis,
                             float(kind.size[0]), reach(kind.shape, kind.size), along))
        return out

    def window(self, track: Track) -> tuple:
        """The reach window [s_in, s_out] (m along the belt) of ``track`` (module docstring)."""
        belt = {b.name: b for b in self.built.station.config.belts}[track.belt]
        local = belt_frame(belt).inverse().multiply(np.asarray(track.position))
        above = grip_height(self.line.kind(track.kind), hand_size(self.scenario.pick.gripper.model)[0])
        return self.window_at(track.belt, float(local[1]), float(local[2]) + above)

    def _scan(self, X, belt, local) -> tuple:
        guess = np.radians(self.scenario.robot.initial_q_deg)
        best, run = (math.inf, -math.inf), []
        for s in np.arange(-belt.length / 2, belt.length / 2 + 1e-9, WINDOW_STEP):
            ok = self.reachable(X.multiply(np.array([s, local[1], local[2]])), guess)
            if ok is not None:
                guess = ok
                run.append(s)
            if run and (ok is None or s + WINDOW_STEP > belt.length / 2):
                if run[-1] - run[0] > best[1] - best[0]:
                    best = (float(run[0]), float(run[-1]))
                run = []
        return best

    def reachable(self, x, guess):
        """IK from above at ``x`` and ``lift_height`` above it: the posture at ``x`` or None."""
        q = inverse_kinematics(self._arm, self._frame, np.asarray(x), guess, down=True)
        lift = PickTaskConfig().lift_height
        if q is None or inverse_kinematics(self._arm, self._frame, np.asarray(x) + [0, 0, lift], q,
                                           down=True) is None:
            return None
        return q

    def window_at(self, belt_name: str, lateral: float, height: float) -> tuple:
        """The reach window [s_in, s_out] along belt ``belt_name`` at ``lateral`` and ``height``
        (m, in the belt's frame; ``window``'s cache)."""
        belt = {b.name: b for b in self.built.station.config.belts}[belt_name]
        key = (belt_name, round(lateral / KEY_STEP), round(height / KEY_STEP))
        if key not in self._windows:
            robot = self.scenario.robot
            cell = (robot.model, robot.end_effector, tuple(robot.initial_q_deg), tuple(belt.center),
                    tuple(belt.direction), belt.length, key[1:], PickTaskConfig().lift_height)
            if cell not in _WINDOWS:
                _WINDOWS[cell] = self._scan(belt_frame(belt), belt, np.array([0.0, KEY_STEP * key[1],
                                                                              KEY_STEP * key[2]]))
            self._windows[key] = _WINDOWS[cell]
        return self._windows[key]
