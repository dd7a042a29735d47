"""The pick station's part tracker — the sensor a pick without a camera aims by — and the
controller side's reading of its reports.

A cell without a camera tracks its parts with a pose tracker (a motion-capture system, or a
tracking filter behind a sensor) that reports, per tracked body, its pose and twist.
``PartTracker`` is that sensor in the station: per part (scenario order) [p (3), v (3), R
row-major (9), ω (3)] (m, m/s, rad/s; the part's centre, world frame), ``TRACKED_SIZE`` doubles a
part, on the station's ``tracked_poses`` port.  The scenario declares no error for it (a pick's
``measurement`` block configures only the rgbd camera): its report is the part's state at the
sample, read from the plant's state and body poses as ``part_pose.PartPoses`` reads them — the
same numbers (a pick's metrics are unchanged by it) — and no acceleration: the plant's
generalized accelerations (the truth ports' ẍ, ω̇) are nothing a tracker reports.  The truth
ports (``part_k_pose``, ``part_k_rotation``) stay the metrics'; the controller side reads this
port alone, in ``ptint run`` and across ``ptint hardware``'s link (``TRACKED_POSES``).

``TrackedParts`` is the controller side's reading of a report: the ``part_k_pose`` (9) and
``part_k_rotation`` (15) inputs of ``targets.PickTargets``, with the accelerations 0 (which the
targets set to 0 anyway: a belt runs at constant speed), by one Drake ``MatrixGain`` (each
output entry 1 × one input entry: exact) and a ``Demultiplexer``.
"""

from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import Demultiplexer, MatrixGain

from ptint_drake.worlds.base import TRACKED_SIZE, TRACKER_PORT


class PartTracker(LeafSystem):
    """Output ``tracked_poses`` (``TRACKED_SIZE`` a part) of the free bodies ``parts`` of
    ``plant`` (module docstring), from its inputs ``body_poses`` and ``state`` (the plant's)."""

    def __init__(self, plant, parts):
        super().__init__()
        nq = plant.num_positions()
        self._poses = self.DeclareAbstractInputPort("body_poses", AbstractValue.Make([RigidTransform()]))
        self._state = self.DeclareVectorInputPort("state", nq + plant.num_velocities())
        # a free body's q = [quaternion; p_WB], v = [ω_WB; v_WB] (``part_pose``)
        self._where = [(int(b.index()), b.floating_positions_start() + 4,
                        nq + b.floating_velocities_start_in_v()) for b in parts]
        self.DeclareVectorOutputPort(TRACKER_PORT, TRACKED_SIZE * len(parts), self._calc,
                                     {self.all_input_ports_ticket()})

    def _calc(self, context, output) -> None:
        poses, x = self._poses.Eval(context), self._state.Eval(context)
        out = np.empty(TRACKED_SIZE * len(self._where))
        for k, (body, p, v) in enumerate(self._where):
            row = out[TRACKED_SIZE * k: TRACKED_SIZE * (k + 1)]
            row[0:3], row[3:6], row[15:18] = x[p:p + 3], x[v + 3:v + 6], x[v:v + 3]
            row[6:15] = poses[body].rotation().matrix().ravel()
        output.SetFromVector(out)


def _reading(count: int) -> np.ndarray:
    """The matrix from a report (``TRACKED_SIZE`` a part) to [x, ẋ, 0 (3), R, ω, 0 (3)] a part."""
    D = np.zeros((24 * count, TRACKED_SIZE * count))
    for k in range(count):
        r, c = 24 * k, TRACKED_SIZE * k
        D[r:r + 6, c:c + 6] = np.eye(6)  # x, ẋ
        D[r + 9:r + 21, c + 6:c + 18] = np.eye(12)  # R, ω
    return D


class TrackedParts(Diagram):
    """Input ``tracked_poses`` (a tracker's report of ``count`` parts); outputs ``part_k_pose`` (9)
    and ``part_k_rotation`` (15) in ``PickTargets``' layout (module docstring)."""

    def __init__(self, count: int):
        super().__init__()
        builder = DiagramBuilder()
        gain = builder.AddNamedSystem("tracked_layout", MatrixGain(_reading(count)))
        split = builder.AddNamedSystem("tracked_split", Demultiplexer([9, 15] * count))
        builder.Connect(gain.get_output_port(), split.get_input_port(0))
        builder.ExportInput(gain.get_input_port(), TRACKER_PORT)
        for k in range(count):
            builder.ExportOutput(split.get_output_port(2 * k), f"part_{k}_pose")
            builder.ExportOutput(split.get_output_port(2 * k + 1), f"part_{k}_rotation")
        builder.BuildInto(self)
