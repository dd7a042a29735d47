"""What an RGB-D camera saw, as PNG files: one colour image with poses drawn on it and one depth
image (near = bright, missing pixels black).  Used by the interception world's and the pick
world's camera frames (``worlds.interception.camera_frames``, ``worlds.pick.camera_frames``).

Each file is the camera's image at its own resolution, pixel for pixel, under a caption band
(``CAPTION_HEIGHT`` px: the title — the run, the part or segment, the time — and what the marks
are); the depth image has a scale beside it (``SCALE_WIDTH`` px: its grey ramp with the depths in
m at the ends, and what black means).

A fitted pose (``part_fit`` fits) is drawn as a cross at its centre — green for a good fit, red
for a rejected one — with a 20 mm line along its yaw when the fit has one (its symmetry > 0);
any other pose (an estimate, the truth) is drawn the same way in the colour it is given.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence

import numpy as np
from PIL import Image, ImageDraw, ImageFont
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


def depth_range(depth: np.ndarray) -> tuple[float, float]:
    """(near, far) m: the 1st and 99th percentiles of the valid depths ((0, 1) when none is)."""
    finite = np.isfinite(depth) & (depth > 0.0)
    if not np.any(finite):
        return 0.0, 1.0
    lo, hi = np.percentile(depth[finite], [1, 99])
    return float(lo), float(hi)


def depth_image(depth: np.ndarray) -> Image.Image:
    """The depth (m, H × W) as an 8-bit image: ``depth_range`` from bright (near) to dark, missing
    pixels (0 or not finite) black."""
    finite = np.isfinite(depth) & (depth > 0.0)
    shade = np.zeros(depth.shape, dtype=np.uint8)
    if np.any(finite):
        lo, hi = depth_range(depth)
        near = np.clip((hi - depth[finite]) / max(hi - lo, 1e-6), 0.0, 1.0)
        shade[finite] = (255 * near).astype(np.uint8)
    return Image.fromarray(shade)


CAPTION_HEIGHT = 40  # px above the camera's image: two lines of text
SCALE_WIDTH = 90  # px right of a depth image: the ramp and its labels
FONT_SIZE = 12


def _font() -> ImageFont.ImageFont:
    return ImageFont.load_default(size=FONT_SIZE)


def captioned(image: Image.Image, lines: Sequence[str], scale: tuple | None = None) -> Image.Image:
    """``image`` under a white caption band of ``lines`` (two at most) and, with ``scale`` = (near,
    far) m, a depth scale on its right; the image's pixels are kept as they are."""
    width = image.width + (SCALE_WIDTH if scale is not None else 0)
    out = Image.new("RGB", (width, image.height + CAPTION_HEIGHT), "white")
    out.paste(image.convert("RGB"), (0, CAPTION_HEIGHT))
    draw, font = ImageDraw.Draw(out), _font()
    for k, line in enumerate(lines[:2]):
        draw.text((4, 3 + 18 * k), line, fill=(0, 0, 0), font=font)
    if scale is not None:
        x0, top, bottom = image.width + 8, CAPTION_HEIGHT + 14, out.height - 30
        for y in range(top, bottom):  # bright (near) at the top, as in the image
            level = round(255 * (bottom - 1 - y) / max(bottom - 1 - top, 1))
            draw.line([(x0, y), (x0 + 14, y)], fill=(level, level, level))
        draw.rectangle([x0, top, x0 + 14, bottom], outline=(0, 0, 0))
        draw.text((x0, CAPTION_HEIGHT), "depth", fill=(0, 0, 0), font=font)
        draw.text((x0 + 18, top - 2), f"{scale[0]:.2f} m", fill=(0, 0, 0), font=font)
        draw.text((x0 + 18, bottom - 12), f"{scale[1]:.2f} m", fill=(0, 0, 0), font=font)
        draw.text((x0, bottom + 4), "black: none", fill=(0, 0, 0), font=font)
    return out


def write_frame(folder: Path, label: str, color: np.ndarray, depth: np.ndarray, fits: Sequence,
                X_WC: RigidTransform, info: CameraInfo, poses: Sequence = (), title: str = "",
                marks: str = "") -> list[str]:
    """``folder/{label}_color.png`` (``color`` H × W × 3 with every finite fit drawn, then each
    of ``poses``: (position, yaw or None, colour)) and ``folder/{label}_depth.png``, each under
    ``title`` (``captioned``); ``marks`` says what the colour image's crosses are (default: the
    fits').  Returns their names relative to ``folder``'s parent."""
    image = Image.fromarray(np.ascontiguousarray(color))
    draw = ImageDraw.Draw(image)
    for fit in fits:
        if np.all(np.isfinite(fit.position)):
            draw_pose(draw, X_WC, info, fit.position, fit.yaw if fit.symmetry > 0.0 else None,
                      GOOD if fit.ok else REJECTED)
    for position, yaw, rgb in poses:
        draw_pose(draw, X_WC, info, position, yaw, rgb)
    marks = marks or "crosses: green = a good fit, red = a rejected fit (line: its yaw)"
    captioned(image, [title or label, marks]).save(folder / f"{label}_color.png")
    lo, hi = depth_range(depth)
    captioned(depth_image(depth), [title or label, "depth image: near = bright"],
              scale=(lo, hi)).save(folder / f"{label}_depth.png")
    return [f"{folder.name}/{label}_color.png", f"{folder.name}/{label}_depth.png"]
