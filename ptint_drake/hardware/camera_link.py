"""A depth camera over the link: Drake's image messages, as Drake's own cameras publish them.

``ApplyCameraConfig`` (``hardware_sim``) publishes a camera's images as one ``lcmt_image_array``
on ``DRAKE_RGBD_CAMERA_IMAGES_<name>`` (``ImageToLcmImageArrayT``); ``LcmImageArrayToImages``
reads them back.  This module writes and reads the same message from Python for a depth image
alone (colour is not used by the perception): one ``lcmt_image``, ``PIXEL_FORMAT_DEPTH``,
``CHANNEL_TYPE_FLOAT32``, little-endian, uncompressed (lossless 32F: the perception sees the
very floats the station rendered), ``header.utime`` = the frame's tick in µs,
``header.frame_name`` = the camera's name.  ``unpack_depth_image`` also reads Drake's cameras'
default, 16-bit depth in mm, zlib-compressed (tests/unit/test_camera_link.py decodes what
``ApplyCameraConfig`` publishes).

A frame crosses with the status of the tick whose state it shows (``frame_due``): the tick t_k
with the frame's time in (t_k, t_k + T] — a station's discrete plant holds after the step at t_k
the state a perception sampling in (t_k, t_k + T] reads (at a frame on a tick, its update and the
plant's step are simultaneous: it reads the state before the step, measured), and
``perception.depth_noise`` draws a frame's noise by round(t · rate), the same for t_k and the
frame's time; the frame at t = 0 comes with the hand-shake (the start, before the first step).
The controller side sets the image when the status comes, before the events of that period, so
its perception samples what ``ptint run``'s does.
"""

from __future__ import annotations

import math
import os
import struct
import urllib.parse
import zlib
from typing import Optional

import numpy as np
from drake import lcmt_image, lcmt_image_array
from pydrake.lcm import DrakeLcm
from pydrake.systems.sensors import ImageDepth32F

from ptint_drake.hardware.link import utime_of

IMAGE_CHANNEL_PREFIX = "DRAKE_RGBD_CAMERA_IMAGES_"  # ApplyCameraConfig's channel names
TIME_TOL = 1e-9  # s


def image_channel(camera: str) -> str:
    """The channel of a camera's images (``ApplyCameraConfig``'s name for it)."""
    return IMAGE_CHANNEL_PREFIX + camera


RECEIVE_BUFFER = 4 * 1024 * 1024  # bytes: a receiver's UDP buffer for depth frames (Linux's rmem_max here)


def with_receive_buffer(url: Optional[str]) -> Optional[str]:
    """``url`` (None: ``LCM_DEFAULT_URL`` or Drake's default) with LCM's ``recv_buf_size`` option
    when it has none: a 424 x 240 float frame is 407 kB, more than the kernel's default UDP receive
    buffer (212,992 bytes here), whose overflow drops a large message's fragments."""
    if url is None:
        url = os.environ.get("LCM_DEFAULT_URL") or DrakeLcm().get_lcm_url()
    parsed = urllib.parse.urlparse(url)
    if parsed.scheme != "udpm" or "recv_buf_size" in urllib.parse.parse_qs(parsed.query):
        return url
    return url + ("&" if parsed.query else "?") + f"recv_buf_size={RECEIVE_BUFFER}"


def frame_due(t: float, period: float, rate_hz: float, handshake: bool = False) -> bool:
    """Whether the status of the tick at ``t`` brings a camera frame (at k / ``rate_hz``): one in
    (t, t + ``period``] — the station's state over that period, which a perception sampling at the
    frame's time sees (at a frame on a tick, the state before that tick's step) — or, for the
    hand-shake (``handshake``), one at t itself (the start: the state before the first step)."""
    k = math.ceil(t * rate_hz - TIME_TOL)
    if handshake:
        return abs(k / rate_hz - t) < TIME_TOL
    if abs(k / rate_hz - t) < TIME_TOL:
        k += 1
    return k / rate_hz < t + period + TIME_TOL


def pack_depth_image(t: float, image: ImageDepth32F, camera: str) -> bytes:
    """An ``lcmt_image_array`` of one depth image (32-bit floats, m) of the tick at ``t``."""
    depth = np.ascontiguousarray(np.asarray(image.data, dtype="<f4").reshape(image.height(), image.width()))
    one = lcmt_image()
    one.header.utime, one.header.frame_name = utime_of(t), camera
    one.width, one.height, one.row_stride = image.width(), image.height(), 4 * image.width()
    one.bigendian = False
    one.pixel_format, one.channel_type = lcmt_image.PIXEL_FORMAT_DEPTH, lcmt_image.CHANNEL_TYPE_FLOAT32
    one.compression_method = lcmt_image.COMPRESSION_METHOD_NOT_COMPRESSED
    one.data = depth.tobytes()
    one.size = len(one.data)
    array = lcmt_image_array()
    array.header.utime, array.header.frame_name = utime_of(t), camera
    array.num_images, array.images = 1, [one]
    return array.encode()


def frame_utime(data: bytes) -> int:
    """The ``header.utime`` of an ``lcmt_image_array`` message, read without decoding the rest
    (LCM's encoding: an 8-byte fingerprint, then the header's int32 ``seq`` and int64 ``utime``,
    big-endian); ValueError when the message is too short to hold one."""
    if len(data) < 20:
        raise ValueError(f"an image message of {len(data)} bytes")
    return struct.unpack(">q", data[12:20])[0]


def unpack_depth_image(data: bytes) -> tuple[int, ImageDepth32F]:
    """(utime, the depth image in m) of an ``lcmt_image_array`` holding one depth image: 32-bit
    floats in m (what ``pack_depth_image`` writes), or 16-bit integers in mm (what Drake's
    ``ApplyCameraConfig`` publishes by default: 0 too close, 65535 too far, read as inf),
    uncompressed or zlib-compressed; ValueError naming what is wrong otherwise."""
    try:
        array = lcmt_image_array.decode(data)
    except Exception as exc:  # noqa: BLE001
        raise ValueError(f"an undecodable image message ({type(exc).__name__})") from None
    depth = [im for im in array.images if im.pixel_format == lcmt_image.PIXEL_FORMAT_DEPTH]
    if len(depth) != 1:
        raise ValueError(f"an image message with {len(depth)} depth images (one needed)")
    one = depth[0]
    kinds = {lcmt_image.CHANNEL_TYPE_FLOAT32: ("f4", 4), lcmt_image.CHANNEL_TYPE_UINT16: ("u2", 2)}
    if one.channel_type not in kinds:
        raise ValueError(f"a depth image of channel type {one.channel_type} (32-bit float or 16-bit mm)")
    raw = one.data
    if one.compression_method == lcmt_image.COMPRESSION_METHOD_ZLIB:
        raw = zlib.decompress(raw)
    elif one.compression_method != lcmt_image.COMPRESSION_METHOD_NOT_COMPRESSED:
        raise ValueError(f"a depth image compressed by method {one.compression_method} (none or zlib)")
    code, size = kinds[one.channel_type]
    pixels = np.frombuffer(raw, dtype=(">" if one.bigendian else "<") + code)
    pixels = pixels.reshape(one.height, one.row_stride // size)[:, :one.width]
    if one.channel_type == lcmt_image.CHANNEL_TYPE_UINT16:
        pixels = np.where(pixels == np.iinfo(np.uint16).max, np.inf, pixels.astype(np.float32) / 1000.0)
    image = ImageDepth32F(one.width, one.height)
    image.mutable_data[:] = pixels.reshape(one.height, one.width, 1)
    return array.header.utime, image
