"""What an RGB-D camera saw, as PNG files: one colour image with poses drawn on it and one depth
image (near = bright, missing pixels black).  Used by the interception world's and the pick
world's camera frames (``worlds.interception.camera_frames``, ``worlds.pick.camera_frames``).

A fitted pose (``part_fit`` fits) is drawn as a cross at its centre — green for a good fit, red
for a rejected one — with a 20 mm line along its yaw when the fit has one (its symmetry > 0);
any other pose (an estimate, the truth) is drawn the same way in the colour it is given.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence

import numpy as np
from PIL import Image, ImageDraw
from pydrake.math import RigidTransform
from pydrake.systems.sensors import CameraInfo

from ptint_drake.systems.perception.rgbd_camera import project

GOOD = (40, 220, 40)  # a good fit's colour (RGB)
REJECTED = (230, 40, 40)  # a rejected fit's colour
YAW_LINE = 0.02  # m, the drawn yaw line's length in the world


def _mark(draw: ImageDraw.ImageDraw, uv, yaw_uv, color: tuple) -> None:
    u, v = uv
    draw.line([(u - 6, v), (u + 6, v)], fill=color, width=2)
    draw.line([(u, v - 6), (u, v + 6)], fill=color, width=2)
    if yaw_uv is not None:
        draw.line([(u, v), tuple(yaw_uv)], fill=color, width=1)


def draw_pose(draw: ImageDraw.ImageDraw, X_WC: RigidTransform, info: CameraInfo, position, yaw,
              color: tuple) -> None:
    """A cross at world ``position`` and, when ``yaw`` is not None, a line along it."""
    yaw_value = 0.0 if yaw is None else yaw
    tip = np.asarray(position, float) + YAW_LINE * np.array([math.cos(yaw_value), math.sin(yaw_value), 0.0])
    uv = project(X_WC, info, np.array([position, tip]))[:, 0:2]
    _mark(draw, uv[0], None if yaw is None else uv[1], color)


def depth_image(depth: np.ndarray) -> Image.Image:
    """The depth (m, H × W) as an 8-bit image: the 1st–99th percentile of the valid depths from
    bright (near) to dark, missing pixels (0 or not finite) black."""
    finite = np.isfinite(depth) & (depth > 0.0)
    shade = np.zeros(depth.shape, dtype=np.uint8)
    if np.any(finite):
        lo, hi = np.percentile(depth[finite], [1, 99])
        near = np.clip((hi - depth[finite]) / max(hi - lo, 1e-6), 0.0, 1.0)
        shade[finite] = (255 * near).astype(np.uint8)
    return Image.fromarray(shade)


def write_frame(folder: Path, label: str, color: np.ndarray, depth: np.ndarray, fits: Sequence,
                X_WC: RigidTransform, info: CameraInfo, poses: Sequence = ()) -> list[str]:
    """``folder/{label}_color.png`` (``color`` H × W × 3 with every finite fit drawn, then each
    of ``poses``: (position, yaw or None, colour)) and ``folder/{label}_depth.png``; returns
    their names relative to ``folder``'s parent."""
    image = Image.fromarray(np.ascontiguousarray(color))
    draw = ImageDraw.Draw(image)
    for fit in fits:
        if np.all(np.isfinite(fit.position)):
            draw_pose(draw, X_WC, info, fit.position, fit.yaw if fit.symmetry > 0.0 else None,
                      GOOD if fit.ok else REJECTED)
    for position, yaw, rgb in poses:
        draw_pose(draw, X_WC, info, position, yaw, rgb)
    image.save(folder / f"{label}_color.png")
    depth_image(depth).save(folder / f"{label}_depth.png")
    return [f"{folder.name}/{label}_color.png", f"{folder.name}/{label}_depth.png"]
