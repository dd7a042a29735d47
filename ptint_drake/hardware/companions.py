"""The companions of a status as ``ptint drive`` receives them: what a station with a gripper
sends before each status of the arm (``World.link_ports``) — the gripper's status, the pose
tracker's report where the station has one, a depth frame where one falls in the
tick's period (``camera_link.frame_due``) — filed by their time stamp until the status of that
time takes them."""

from __future__ import annotations

import time
from typing import Optional

import numpy as np

from ptint_drake.hardware.camera_link import frame_due, frame_utime, image_channel, unpack_depth_image
from ptint_drake.hardware.link import (TRACKER_CHANNEL, WSG_STATUS_CHANNEL, Endpoint, unpack_tracked,
                                       unpack_wsg_status)


class CompanionFault(Exception):
    """A companion rejected or missing (the message is the one-line reason)."""


def companion_channels(ports) -> tuple:
    """The channels a station's companions of a status arrive on (``World.link_ports``): the
    gripper's status, the tracker's reports where the station has one, the camera's frames."""
    if ports is None:
        return ()
    return ((WSG_STATUS_CHANNEL,) + ((TRACKER_CHANNEL,) if ports.objects else ())
            + ((image_channel(ports.camera),) if ports.camera else ()))


class CompanionInbox:
    """The companions received, by ``utime`` (module docstring); ``ports``: the station's
    ``LinkPorts``, ``period``: T (s), ``timeout``: s to wait for a status's companions."""

    def __init__(self, endpoint: Endpoint, ports, period: float, timeout: float, raw_frames: bool = False):
        self.endpoint, self.ports, self.period, self.timeout = endpoint, ports, period, timeout
        # a depth frame kept as received (its bytes; only its time stamp read here): a process of
        # its own decodes it (``FrameProcess``), not the control loop
        self.raw_frames = raw_frames
        # utime → {"gripper": [fingers; forces], "tracked": a tracker's report, "image": a depth frame}
        self.companions: dict[int, dict] = {}
        self.lost = 0  # ticks skipped for a lost companion (``take``)

    def collect(self) -> None:
        """File the gripper statuses, tracker reports and depth frames received by their ``utime``."""
        for data in self.endpoint.take_side(WSG_STATUS_CHANNEL):
            try:
                utime, fingers, force = unpack_wsg_status(data)
            except ValueError as exc:
                raise CompanionFault(f"gripper status rejected: {exc}; stopped commanding") from None
            self.companions.setdefault(utime, {})["gripper"] = np.concatenate([fingers, force])
        if self.ports.objects:
            for data in self.endpoint.take_side(TRACKER_CHANNEL):
                try:
                    utime, report = unpack_tracked(data, self.ports.objects)
                except ValueError as exc:
                    raise CompanionFault(f"tracker message rejected: {exc}; stopped commanding") from None
                self.companions.setdefault(utime, {})["tracked"] = report
        if self.ports.camera:
            for data in self.endpoint.take_side(image_channel(self.ports.camera)):
                try:
                    utime, image = (frame_utime(data), data) if self.raw_frames else unpack_depth_image(data)
                except ValueError as exc:
                    raise CompanionFault(f"camera frame rejected: {exc}; stopped commanding") from None
                self.companions.setdefault(utime, {})["image"] = image

    def expected(self, utime: int, handshake: bool = False) -> tuple:
        """The companions a status of ``utime`` brings: the gripper's, the tracker's report where the
        station has one, and a depth frame where one falls in the tick's period (``frame_due``)."""
        ports = self.ports
        frame = bool(ports.camera) and frame_due(utime * 1e-6, self.period, ports.camera_rate_hz, handshake)
        return ("gripper",) + (("tracked",) if ports.objects else ()) + (("image",) if frame else ())

    def take(self, utime: int, handshake: bool = False) -> Optional[dict]:
        """The companions of the tick ``utime`` (``_expected``; the hardware sends them before the
        arm's status; in lockstep a lost one comes again with the status's re-send).  None when
        one of them is lost: a later tick's companions came while this tick's set is incomplete
        (one publishing socket on the hardware side: its packets arrive in order, so the missing
        one will not come; in real time nothing re-sends it) — the tick is skipped, as a lost
        status is.  ``CompanionFault`` after the status timeout without them."""
        deadline = time.perf_counter() + self.timeout
        expected = self.expected(utime, handshake)
        while True:
            self.collect()
            got = self.companions.get(utime, {})
            if all(k in got for k in expected):
                # taken: the next status of this time (the first tick after the hand-shake's)
                # waits for its own
                for old in [u for u in self.companions if u <= utime]:
                    del self.companions[old]
                return got
            if not handshake and any(u > utime for u in self.companions):
                self.lost += 1
                for old in [u for u in self.companions if u <= utime]:
                    del self.companions[old]
                return None
            if time.perf_counter() >= deadline:
                missing = " and ".join(k for k in expected if k not in got)
                raise CompanionFault(
                    f"no {missing} message for the status of t = {utime / 1e6:.3f} s within "
                    f"{self.timeout:g} s: stopped commanding"
                )
            self.endpoint.pump(0.005)  # the arm's statuses stay in the inbox

