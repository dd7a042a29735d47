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
3. The sphere: the centre c minimising Σ(|p_i − c| − R)² over the segment's points (back-projected
   with ``rgbd_camera.cloud_camera_info``, put in the world by the camera's configured pose), by
   ``scipy.optimize.least_squares`` from the points' centroid moved R back along the viewing ray.
   The radius is known (the ball is the scene's one sphere of that size), so a visible cap of the
   sphere fixes c; a free radius on a cap this small (25–100 pixels at 1.4–2.6 m) is ill-posed.
4. Accepted when the fit's RMS residual is below ``RESIDUAL`` (the noise of the D415 model at
   that depth, ``depth_noise.depth_sigma``, × 3, plus 2 mm); of several, the one with the least
   residual.

``BallCamera`` is the formula ``Camera``'s delay buffer and output (a frame taken at t_k is
visible at t_k + latency) with the sample taken from the depth image instead of the truth: its
``x_true`` input stays unconnected; a frame with no ball is stored invalid (the estimator then
predicts only).

The estimator's assumed noise (``FIT_STD``): the fits' error against the true centre, measured on
throws 0–3 (every frame with a fit, camera of ``catch_toss_iiwa14_rgbd``): docs/catch.md.
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
FIT_STD = 0.003  # m, what the estimator assumes of a fit (module docstring)


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


def _points(depth: np.ndarray, rows: np.ndarray, cols: np.ndarray, info: CameraInfo,
            X_WC: RigidTransform) -> np.ndarray:
    """World points (N × 3) of the pixels (rows, cols)."""
    z = depth[rows, cols].astype(float)
    x = (cols - info.center_x()) * z / info.focal_x()
    y = (rows - info.center_y()) * z / info.focal_y()
    return X_WC.multiply(np.vstack([x, y, z])).T


def _sphere(points: np.ndarray, radius: float, eye: np.ndarray) -> tuple:
    """The centre of the sphere of ``radius`` fitted to ``points`` (step 3) and its RMS residual."""
    mean = points.mean(axis=0)
    ray = (mean - eye) / np.linalg.norm(mean - eye)
    fit = least_squares(lambda c: np.linalg.norm(points - c, axis=1) - radius, mean + radius * ray,
                        method="lm")
    return fit.x, float(np.sqrt(np.mean(fit.fun ** 2)))


def find_ball(depth: np.ndarray, info: CameraInfo, X_WC: RigidTransform, radius: float) -> Optional[np.ndarray]:
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
        centre, residual = _sphere(_points(depth, rows, cols, cloud_info, X_WC), radius, X_WC.translation())
        if residual < RESIDUAL * float(depth_sigma(z)) + RESIDUAL_FLOOR and residual < best_residual:
            best, best_residual = centre, residual
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

    def _new_slot(self, context, t: float) -> np.ndarray:
        depth = np.asarray(self._depth_in.Eval(context).data)[:, :, 0]
        centre = find_ball(depth, self._info, self._X_WC, self._radius)
        if centre is None:
            return np.array([t, 0.0, 0.0, 0.0, 0.0])
        return np.array([t, *centre, 1.0])
