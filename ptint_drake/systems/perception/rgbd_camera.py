"""The RGB-D camera: Drake's ``RgbdSensor`` on a ``RenderEngineVtk`` (headless), fixed in the
world, followed by the D415-style ``DepthNoise``.

``camera_pose(config)`` is X_WC from ``xyz`` + ``rpy_deg`` or ``look_at`` + ``look_from``
(Drake's camera frame: +z along the optical axis, +x right and +y down in the image; with
``look_at`` the image's down direction is the one closest to world −z).  ``AddRgbdCamera``
adds the renderer to a ``SceneGraph`` (once), the sensor, and the noise; it returns the ports
a perception pipeline reads: ``color_image`` and the noisy ``depth_image``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydrake.geometry import (ClippingRange, ColorRenderCamera, DepthRange, DepthRenderCamera,
                              MakeRenderEngineVtk, RenderCameraCore, RenderEngineVtkParams, SceneGraph)
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.systems.framework import DiagramBuilder, OutputPort
from pydrake.systems.sensors import CameraInfo, RgbdSensor

from ptint_drake.config.measurement import RgbdCameraConfig
from ptint_drake.systems.perception.depth_noise import DepthNoise

RENDERER = "ptint_vtk"
NEAR, FAR = 0.05, 5.0  # m, clipping of the colour camera
DEPTH_NEAR, DEPTH_FAR = 0.10, 3.0  # m, the depth camera's range (beyond: too far)


def _field_error(name: str, message: str) -> ValueError:
    return ValueError(f"measurement.camera.{name}: {message}")


def _vector(value, name: str) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise _field_error(name, f"must be 3 numbers, got {value!r}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise _field_error(name, f"must be 3 finite numbers, got {value!r}")
    return v


def validate_camera(c: RgbdCameraConfig) -> None:
    """Raise ``ValueError`` with a one-line message naming the first bad field."""
    for name in ("width", "height"):
        value = getattr(c, name)
        if isinstance(value, bool) or not isinstance(value, int) or not 16 <= value <= 4096:
            raise _field_error(name, f"must be an integer in [16, 4096], got {value!r}")
    if not (isinstance(c.fov_y_deg, (int, float)) and 1.0 <= c.fov_y_deg <= 150.0):
        raise _field_error("fov_y_deg", f"must be in [1, 150] deg, got {c.fov_y_deg!r}")
    if not (isinstance(c.depth_noise_scale, (int, float)) and 0.0 <= c.depth_noise_scale <= 100.0):
        raise _field_error("depth_noise_scale", f"must be in [0, 100], got {c.depth_noise_scale!r}")
    if c.part_shape not in ("box", "cylinder"):
        raise _field_error("part_shape", f"must be box or cylinder, got {c.part_shape!r}")
    n = 3 if c.part_shape == "box" else 2
    if len(c.part_size) != n or not all(isinstance(v, (int, float)) and v > 0 for v in c.part_size):
        raise _field_error("part_size", f"a {c.part_shape} needs {n} sizes > 0 (m), got {c.part_size!r}")
    posed = c.xyz is not None or c.rpy_deg is not None
    aimed = c.look_at is not None or c.look_from is not None
    if posed == aimed:
        raise _field_error("xyz", "give the camera's pose as xyz + rpy_deg or as look_at + look_from")
    if posed:
        for name in ("xyz", "rpy_deg"):
            _vector(getattr(c, name), name)
    else:
        at, eye = _vector(c.look_at, "look_at"), _vector(c.look_from, "look_from")
        if np.linalg.norm(at - eye) < 1e-6:
            raise _field_error("look_at", "must differ from look_from")
    if c.pose_error and (len(c.pose_error) != 6 or not np.all(np.isfinite(np.asarray(c.pose_error, float)))):
        raise _field_error("pose_error", "[dx, dy, dz (m), droll, dpitch, dyaw (deg)] or [], "
                           f"got {c.pose_error!r}")
    for i, belt in enumerate(c.belts):
        _vector(belt.center, f"belts[{i}].center")
        d = _vector(belt.direction, f"belts[{i}].direction")
        if math.hypot(d[0], d[1]) < 1e-6:
            raise _field_error(f"belts[{i}].direction", "must have a horizontal component")
        if not (belt.length > 0 and belt.width > 0):
            raise _field_error(f"belts[{i}].length", "length and width must be > 0")


def camera_pose(c: RgbdCameraConfig) -> RigidTransform:
    """X_WC of the configured camera (see the module docstring)."""
    if c.xyz is not None:
        return RigidTransform(RollPitchYaw(np.radians(c.rpy_deg)), np.asarray(c.xyz, dtype=float))
    eye, at = np.asarray(c.look_from, dtype=float), np.asarray(c.look_at, dtype=float)
    z = (at - eye) / np.linalg.norm(at - eye)
    down = np.array([0.0, 0.0, -1.0])
    y = down - (down @ z) * z
    if np.linalg.norm(y) < 1e-6:  # looking straight down: image down is world −x
        y = np.array([-1.0, 0.0, 0.0]) - z[0] * z
    y /= np.linalg.norm(y)
    x = np.cross(y, z)
    return RigidTransform(RotationMatrix(np.column_stack([x, y, z])), eye)


def camera_info(c: RgbdCameraConfig) -> CameraInfo:
    """The configured intrinsics (width, height, vertical field of view)."""
    return CameraInfo(c.width, c.height, math.radians(c.fov_y_deg))


# px: where Drake's rendered depth (RgbdSensor on RenderEngineVtk) puts a scene point, against
# where the same CameraInfo's pinhole back-projection (DepthImageToPointCloud) expects it, in u and
# v.  Measured (issue 34): a 30 mm cube 0.5 m below a camera tilted 20-35°, noiseless, fitted from
# the cloud — back-projected with CameraInfo's own principal point, every fit is off by half a
# pixel footprint in both image axes (conveyor_pick_place_rgbd's camera: 0.6 mm x, 0.7 mm y,
# +0.3 mm z at yaw 20° and 45°, at two places 50 mm apart, on Drake 1.51.1 and 1.58); with the
# principal point 0.5 px lower in u and v, ≤ 0.04 mm.
RENDER_PIXEL_SHIFT = -0.5


def cloud_camera_info(info: CameraInfo) -> CameraInfo:
    """The intrinsics that back-project a depth image Drake rendered with ``info`` onto the scene:
    ``info``'s, the principal point moved by ``RENDER_PIXEL_SHIFT`` in u and v."""
    return CameraInfo(info.width(), info.height(), info.focal_x(), info.focal_y(),
                      info.center_x() + RENDER_PIXEL_SHIFT, info.center_y() + RENDER_PIXEL_SHIFT)


def tilt_deg(X_WC: RigidTransform) -> float:
    """Angle (deg) of the optical axis from straight down."""
    z = X_WC.rotation().matrix()[:, 2]
    return math.degrees(math.acos(max(-1.0, min(1.0, -z[2]))))


def describe_pose(c: RgbdCameraConfig) -> str:
    """The configured pose as the scenario writes it (for one-line messages)."""
    if c.xyz is not None:
        return f"xyz={list(c.xyz)} rpy_deg={list(c.rpy_deg)}"
    return f"look_from={list(c.look_from)} look_at={list(c.look_at)}"


def project(X_WC: RigidTransform, info: CameraInfo, p_W: np.ndarray) -> np.ndarray:
    """Pixel coordinates (N × 2) and depth (N) of world points p_W (N × 3): [u, v, z]."""
    p_C = (X_WC.inverse().multiply(np.asarray(p_W, dtype=float).T)).T
    z = p_C[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        u = info.focal_x() * p_C[:, 0] / z + info.center_x()
        v = info.focal_y() * p_C[:, 1] / z + info.center_y()
    return np.column_stack([u, v, z])


def in_view(X_WC: RigidTransform, info: CameraInfo, p_W: np.ndarray, margin_px: float = 0.0) -> np.ndarray:
    """Whether each world point is in front of the camera, within its depth range and image."""
    uvz = project(X_WC, info, p_W)
    u, v, z = uvz.T
    return ((z > DEPTH_NEAR) & (z < DEPTH_FAR) & (u >= margin_px) & (u <= info.width() - margin_px)
            & (v >= margin_px) & (v <= info.height() - margin_px))


@dataclass
class RgbdCamera:
    """What ``AddRgbdCamera`` added: the sensor, the noise, their ports and the camera's
    intrinsics and pose."""

    sensor: RgbdSensor
    noise: DepthNoise
    color_image: OutputPort
    depth_image: OutputPort  # noisy, ImageDepth32F
    info: CameraInfo
    X_WC: RigidTransform


def AddRenderer(scene_graph: SceneGraph) -> None:
    """A headless VTK renderer named ``RENDERER`` (once per scene graph)."""
    if not scene_graph.HasRenderer(RENDERER):
        scene_graph.AddRenderer(RENDERER, MakeRenderEngineVtk(RenderEngineVtkParams()))


def AddRgbdCamera(builder: DiagramBuilder, scene_graph: SceneGraph, config: RgbdCameraConfig, *,
                  rate_hz: float, seed: int, name: str = "rgbd_camera") -> RgbdCamera:
    """The camera of ``config`` rendering ``scene_graph`` (see the module docstring)."""
    validate_camera(config)
    AddRenderer(scene_graph)
    info = camera_info(config)
    core = RenderCameraCore(RENDERER, info, ClippingRange(NEAR, FAR), RigidTransform())
    X_WC = camera_pose(config)
    X_rendered = X_WC
    if config.pose_error:  # the real camera, off its calibration (the perception keeps X_WC)
        e = np.asarray(config.pose_error, dtype=float)
        X_rendered = X_WC.multiply(RigidTransform(RollPitchYaw(np.radians(e[3:6])), e[0:3]))
    sensor = builder.AddNamedSystem(name, RgbdSensor(
        scene_graph.world_frame_id(), X_rendered, ColorRenderCamera(core, False),
        DepthRenderCamera(core, DepthRange(DEPTH_NEAR, DEPTH_FAR))))
    builder.Connect(scene_graph.get_query_output_port(), sensor.query_object_input_port())
    noise = builder.AddNamedSystem(f"{name}_depth_noise", DepthNoise(
        info, rate_hz=rate_hz, seed=seed, scale=config.depth_noise_scale))
    builder.Connect(sensor.depth_image_32F_output_port(), noise.get_input_port())
    return RgbdCamera(sensor, noise, sensor.color_image_output_port(), noise.get_output_port(), info, X_WC)
