"""The catch world's rendered ball camera (issue 46, ``measurement.sensor: rgbd``): the ball's
centre found in each depth frame of the station's ``RgbdSensor`` (``perception.rgbd_camera``:
VTK, the D415-style depth noise), with no truth, delivered on the formula camera's timing.

``find_ball`` (one frame, no memory):

1. Segments: the valid depth pixels split where neighbouring pixels' depths jump by more than
   ``JUMP`` (the ball in front of the arm, or the arm in front of the ball, is a jump; a sphere's
   own surface at these ranges is not), connected components (``scipy.ndimage.label``).
2. Ball-sized: a segment whose pixel count and extent fit the disc a sphere of the ball's radius
   R projects to at the segment's median depth (at most ``SIZE_SLACK`` × its area and its
   diameter + 2 px; at least ``MIN_PIXELS`` and ``MIN_FILL`` of the disc: a sliver of an arm's
   link fragmented by the noise can fit a sphere's cap).  The arm's links and the hand are larger; what the
   hand hides of the ball late in a catch makes the segment too small or merges it with the hand
   (a jump < ``JUMP``): the frame is then a dropout for the estimator.
3. The sphere: its centre on the viewing ray through the segment's pixel centroid (a sphere's
   disc is centred on its centre's image), at the distance s minimising Σ(|p_i − s·ray| − R)²
   over the segment's points (back-projected with ``rgbd_camera.cloud_camera_info``), by
   ``scipy.optimize.least_squares``; put in the world by the camera's configured pose.  The
   radius is known (the ball is the scene's one sphere of that size).  A free centre (three
   numbers) on a cap this small (25–100 pixels at 1.4–2.7 m) slid sideways on the depth noise:
   measured on still frames at 2.75 m, 7.4 mm lateral scatter; the disc's centroid fixes the
   lateral position from the silhouette, which the depth noise does not move.
4. Accepted when the fit's RMS residual is below ``RESIDUAL`` (the noise of the D415 model at
   that depth, ``depth_noise.depth_sigma``, × 3, plus 2 mm); of several, the one with the least
   residual.

``BallCamera`` is the formula ``Camera``'s delay buffer and output (a frame taken at t_k is
visible at t_k + latency) with the sample taken from the depth image instead of the truth: its
``x_true`` input stays unconnected; a frame with no ball is stored invalid (the estimator then
predicts only).

The estimator's assumed noise (``FIT_STD``, 2 mm per axis): the fits' error against the true
centre on still frames of ``catch_toss_iiwa14_rgbd``'s camera (20 noise draws at each of three
places 2.1–2.75 m away): 0.4–1.0 mm across the view, 1.0–2.4 mm along it, biases ≤ 1.3 mm.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.math import RigidTransform
from pydrake.systems.sensors import CameraInfo, ImageDepth32F
from scipy import ndimage
from scipy.optimize import least_squares

from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.systems.perception.camera import Camera
from ptint_drake.systems.perception.depth_noise import depth_sigma
from ptint_drake.systems.perception.rgbd_camera import DEPTH_FAR, cloud_camera_info

JUMP = 0.04  # m, a depth step between neighbouring pixels that separates two segments
MIN_PIXELS = 8
SIZE_SLACK = 1.6  # × the projected disc's area
MIN_FILL = 0.35  # × the projected disc's area
RESIDUAL = 3.0  # × the depth noise's σ at the segment's depth (+ RESIDUAL_FLOOR)
RESIDUAL_FLOOR = 0.002  # m
FIT_STD = 0.002  # m, what the estimator assumes of a fit (module docstring)


def _segments(depth: np.ndarray) -> tuple:
    """Labels of the valid pixels' segments (step 1) and their count."""
    valid = np.isfinite(depth) & (depth > 0.0) & (depth < DEPTH_FAR)
    d = np.where(valid, depth, np.nan)
    cut = np.zeros_like(valid)
    with np.errstate(invalid="ignore"):
        jump_u = np.abs(np.diff(d, axis=1)) > JUMP
        jump_v = np.abs(np.diff(d, axis=0)) > JUMP
    cut[:, :-1] |= jump_u
    cut[:, 1:] |= jump_u
    cut[:-1, :] |= jump_v
    cut[1:, :] |= jump_v
    return ndimage.label(valid & ~cut)


def _camera_points(depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, info: CameraInfo) -> np.ndarray:
    """Camera-frame points (N × 3) of the pixels (rows, cols)."""
    z = depth[rows, cols].astype(float)
    return np.column_stack([(cols - info.center_x()) * z / info.focal_x(),
                            (rows - info.center_y()) * z / info.focal_y(), z])


def _sphere(points: np.ndarray, ray: np.ndarray, radius: float) -> tuple:
    """The centre s·ray (camera frame) of the sphere of ``radius`` fitted to ``points`` along the
    unit ``ray`` (step 3) and the fit's RMS residual."""
    s0 = float(np.median(points @ ray)) + radius
    fit = least_squares(lambda s: np.linalg.norm(points - s[0] * ray, axis=1) - radius, [s0], method="lm")
    return fit.x[0] * ray, float(np.sqrt(np.mean(fit.fun ** 2)))


def find_ball(depth: np.ndarray, info: CameraInfo, X_WC: RigidTransform,
              radius: float) -> Optional[np.ndarray]:
    """The ball's centre (world, m) in one depth frame (module docstring), or None."""
    labels, count = _segments(depth)
    if count == 0:
        return None
    cloud_info = cloud_camera_info(info)
    f = info.focal_y()
    sizes = np.bincount(labels.ravel(), minlength=count + 1)
    best, best_residual = None, np.inf
    for index, box in enumerate(ndimage.find_objects(labels), start=1):
        n = sizes[index]
        if box is None or n < MIN_PIXELS:
            continue
        rows, cols = np.nonzero(labels[box] == index)
        rows, cols = rows + box[0].start, cols + box[1].start
        z = float(np.median(depth[rows, cols]))
        r_px = f * radius / z
        extent = max(box[0].stop - box[0].start, box[1].stop - box[1].start)
        disc = np.pi * r_px ** 2
        if not MIN_FILL * disc <= n <= SIZE_SLACK * disc + 4 or extent > 2.0 * r_px + 2:
            continue
        ray = np.array([(cols.mean() - cloud_info.center_x()) / cloud_info.focal_x(),
                        (rows.mean() - cloud_info.center_y()) / cloud_info.focal_y(), 1.0])
        points = _camera_points(depth, rows, cols, cloud_info)
        centre, residual = _sphere(points, ray / np.linalg.norm(ray), radius)
        if residual < RESIDUAL * float(depth_sigma(z)) + RESIDUAL_FLOOR and residual < best_residual:
            best, best_residual = X_WC.multiply(centre), residual
    return best


class BallCamera(Camera):
    """The ball's centre found in the depth frames (module docstring).  Input ``depth_image``
    (``ImageDepth32F``: the station's noisy depth); output ``measurement`` (5): [stamp, x, y, z,
    valid] of the newest visible frame, as ``Camera``'s."""

    def __init__(self, *, config: MeasurementConfig, info: CameraInfo, X_WC: RigidTransform, radius: float):
        super().__init__(config=config)
        self._info, self._X_WC, self._radius = info, X_WC, float(radius)
        self._depth_in = self.DeclareAbstractInputPort(
            "depth_image", AbstractValue.Make(ImageDepth32F(info.width(), info.height())))

    def get_depth_image_input_port(self):
        return self._depth_in

    @property
    def info(self) -> CameraInfo:
        """The camera's intrinsics (as rendered)."""
        return self._info

    @property
    def X_WC(self) -> RigidTransform:
        """The camera's configured pose."""
        return self._X_WC

    def _new_slot(self, context, t: float) -> np.ndarray:
        depth = np.asarray(self._depth_in.Eval(context).data)[:, :, 0]
        centre = find_ball(depth, self._info, self._X_WC, self._radius)
        if centre is None:
            return np.array([t, 0.0, 0.0, 0.0, 0.0])
        return np.array([t, *centre, 1.0])
