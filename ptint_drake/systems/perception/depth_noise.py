"""``DepthNoise`` — the errors of a stereo depth camera in the style of an Intel RealSense D415,
applied to a noiseless rendered depth image.

What it models, per pixel of frame k (k = round(t · rate), so a frame's noise depends only on
k and the seed: ``numpy.random.default_rng([seed, k])``):

- depth noise growing with depth²: σ_z(z) = scale · z² · s / (f · B), the RMS error formula of
  Intel's D400 documentation ("Intel RealSense D400 Series Product Family Datasheet", rev. 9+,
  §4 depth quality, and the white paper "Tuning depth cameras for best performance", 2019:
  RMS error = distance² × subpixel / (focal length in pixels × baseline)), with the D415's
  baseline B = 55 mm, its focal length f ≈ 1000 px at 1280 × 720 (65° horizontal field of
  view) and the typical subpixel accuracy s = 0.08: σ_z = 1.45e-3 · z² (m), 0.36 mm at 0.5 m.
  The noise is that of the real sensor, not rescaled to the simulated image's resolution;
- missing pixels at grazing angles: a pixel whose surface is seen at an incidence θ (between
  the viewing ray and the surface normal, estimated from the neighbouring pixels) is missing
  with a probability rising linearly from 0 at θ = 65° to 1 at 85° (stereo matching fails on
  foreshortened texture; the angles are this model's assumption, the datasheet gives none);
- missing pixels at edges: a pixel next to a depth jump larger than 10 mm is missing with
  probability 0.5 (the D4xx's "invalid band" and its edge filtering; an assumption of the same
  kind);
- a minimum depth: the D415's Min-Z, 0.16 m at 424 × 240 (datasheet table "Depth module
  minimum depth"), closer pixels are missing.

Missing pixels are 0 (Drake's "too close" value), which ``DepthImageToPointCloud`` drops (NaN).
The per-pixel arithmetic is one compiled pass (``_noisy_pixels``: numba, float32, the operations
and their order of the array form it replaced, so the image is the same to the last bit on the
frames of tests/unit/test_perception.py); the random draws stay numpy's (``default_rng([seed,
k])``: the same stream).  ≈ 11 ms → ≈ 2.5 ms a 424 × 240 frame (measured, issue 34).
Not modelled: the IR projector's pattern, temporal correlation, the sensor's own resolution
and filtering, rolling shutter, multipath on shiny parts.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem
from pydrake.systems.sensors import CameraInfo, ImageDepth32F

# D415 (Intel RealSense D400 Series datasheet): baseline 55 mm; focal length ≈ 1000 px at
# 1280 × 720 with 65° horizontal FOV (640 / tan 32.5°); typical subpixel accuracy 0.08.
D415_BASELINE = 0.055  # m
D415_FOCAL_PX = 1005.0  # px
D415_SUBPIXEL = 0.08  # px
D415_MIN_Z = 0.16  # m
NOISE_PER_Z2 = D415_SUBPIXEL / (D415_FOCAL_PX * D415_BASELINE)  # 1/m: σ_z = NOISE_PER_Z2 · z²
GRAZING_FROM_DEG = 65.0
GRAZING_TO_DEG = 85.0
EDGE_JUMP = 0.010  # m
EDGE_MISSING = 0.5


def depth_sigma(z, scale: float = 1.0):
    """σ_z (m) at depth z (m) of the D415-style model."""
    return scale * NOISE_PER_Z2 * np.asarray(z) ** 2


def _rays(info: CameraInfo) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, (x / z, y / z) of its viewing ray in the camera frame (float32)."""
    u = (np.arange(info.width(), dtype=np.float32) - info.center_x()) / info.focal_x()
    v = (np.arange(info.height(), dtype=np.float32) - info.center_y()) / info.focal_y()
    shape = (info.height(), info.width())
    return np.broadcast_to(u, shape), np.broadcast_to(v[:, None], shape)


_DEGREES = np.float32(180.0) / np.float32(np.pi)  # numpy's float32 degrees factor


@njit(cache=True, error_model="numpy")  # (0 / 0: NaN, as numpy)
def _noisy_pixels(z, rx, ry, draw, normal, sigma_per_z2, cos_from2, cos_to2, grazing_from, grazing_span,
                  edge_jump, edge_missing, min_z, out):  # pragma: no cover  (compiled)
    """``noisy_depth``'s arithmetic per pixel (float32 throughout, the array form's order):
    ``z`` (H × W, raw), ``rx`` (W), ``ry`` (H): the rays' x / z and y / z; ``draw`` (2 × H × W)
    and ``normal`` (H × W): the frame's draws; result in ``out``."""
    h, w = z.shape
    zero = np.float32(0.0)
    zz = np.empty((h, w), np.float32)
    for i in range(h):
        for j in range(w):
            v = z[i, j]
            zz[i, j] = v if (np.isfinite(v) and v > zero) else zero
    for i in range(h):
        for j in range(w):
            d = zz[i, j]
            grazing_p = zero
            if 0 < i < h - 1 and 0 < j < w - 1:  # (the border has no central difference: no normal)
                x, y = rx[j] * d, ry[i] * d
                dux = rx[j + 1] * zz[i, j + 1] - rx[j - 1] * zz[i, j - 1]
                duy = ry[i] * zz[i, j + 1] - ry[i] * zz[i, j - 1]
                duz = zz[i, j + 1] - zz[i, j - 1]
                dvx = rx[j] * zz[i + 1, j] - rx[j] * zz[i - 1, j]
                dvy = ry[i + 1] * zz[i + 1, j] - ry[i - 1] * zz[i - 1, j]
                dvz = zz[i + 1, j] - zz[i - 1, j]
                nx, ny, nz = duy * dvz - duz * dvy, duz * dvx - dux * dvz, dux * dvy - duy * dvx
                dot = nx * x + ny * y + nz * d
                cos2 = dot * dot / ((nx * nx + ny * ny + nz * nz) * (x * x + y * y + d * d))
                if cos2 < cos_from2:  # (NaN: not grazing)
                    c = min(max(cos2, cos_to2), cos_from2)
                    angle = np.float32(np.arccos(np.sqrt(c))) * _DEGREES
                    grazing_p = (angle - grazing_from) / grazing_span
            jump = ((j > 0 and abs(d - zz[i, j - 1]) > edge_jump)
                    or (j < w - 1 and abs(zz[i, j + 1] - d) > edge_jump)
                    or (i > 0 and abs(d - zz[i - 1, j]) > edge_jump)
                    or (i < h - 1 and abs(zz[i + 1, j] - d) > edge_jump))
            missing = (draw[0, i, j] < grazing_p) or (jump and draw[1, i, j] < edge_missing) or d < min_z
            v = z[i, j]
            if not (np.isfinite(v) and v > zero):
                out[i, j] = v
            elif missing:
                out[i, j] = zero
            else:
                out[i, j] = d + normal[i, j] * sigma_per_z2 * d * d


def noisy_depth(depth: np.ndarray, info: CameraInfo, rng: np.random.Generator, scale: float = 1.0,
                rays: tuple | None = None) -> np.ndarray:
    """``depth`` (H × W, m; inf or 0 where nothing) with the errors of the module docstring.
    ``scale`` multiplies the noise (0: the image is returned unchanged)."""
    z = np.ascontiguousarray(depth, dtype=np.float32)
    if scale <= 0.0:
        return z.copy()
    rx, ry = rays if rays is not None else _rays(info)
    draw = rng.random((2, *z.shape), dtype=np.float32)
    normal = rng.standard_normal(z.shape, dtype=np.float32)
    cos_from, cos_to = math.cos(math.radians(GRAZING_FROM_DEG)), math.cos(math.radians(GRAZING_TO_DEG))
    f32 = np.float32
    out = np.empty_like(z)
    _noisy_pixels(z, np.ascontiguousarray(rx[0]), np.ascontiguousarray(ry[:, 0]), draw, normal,
                  f32(scale * NOISE_PER_Z2), f32(cos_from ** 2), f32(cos_to ** 2), f32(GRAZING_FROM_DEG),
                  f32(GRAZING_TO_DEG - GRAZING_FROM_DEG), f32(EDGE_JUMP), f32(EDGE_MISSING), f32(D415_MIN_Z),
                  out)
    return out


class DepthNoise(LeafSystem):
    """Input ``depth_image`` (ImageDepth32F, noiseless); output ``depth_image`` (ImageDepth32F)
    with the module docstring's errors for the frame at the context's time (frame k =
    round(t · ``rate_hz``), noise from ``default_rng([seed, k])``)."""

    def __init__(self, info: CameraInfo, *, rate_hz: float, seed: int, scale: float = 1.0):
        super().__init__()
        self._info, self._rate, self._seed, self._scale = info, float(rate_hz), int(seed), float(scale)
        self._rays = _rays(info)
        # the compiled pass loaded (or compiled: once per machine) while the diagram is built
        noisy_depth(np.ones((3, 3), np.float32), CameraInfo(3, 3, 1.0), np.random.default_rng(0))
        blank = AbstractValue.Make(ImageDepth32F(info.width(), info.height()))
        self._in = self.DeclareAbstractInputPort("depth_image", blank)
        self._out = self.DeclareAbstractOutputPort(
            "depth_image", lambda: AbstractValue.Make(ImageDepth32F(info.width(), info.height())),
            self._calc, prerequisites_of_calc={self.time_ticket(), self.all_input_ports_ticket()})

    def _calc(self, context, output) -> None:
        image = self._in.Eval(context)
        k = round(context.get_time() * self._rate)
        rng = np.random.default_rng([self._seed, max(k, 0)])
        depth = noisy_depth(np.asarray(image.data)[:, :, 0], self._info, rng, self._scale, self._rays)
        out = output.get_mutable_value()
        out.mutable_data[:, :, 0] = depth

    def frame_index(self, t: float) -> int:
        return round(t * self._rate)


def pixel_footprint(info: CameraInfo, z: float) -> float:
    """m per pixel at depth z."""
    return z / info.focal_y()


def vertical_fov(info: CameraInfo) -> float:
    """rad: the camera's vertical field of view."""
    return 2.0 * math.atan(0.5 * info.height() / info.focal_y())
