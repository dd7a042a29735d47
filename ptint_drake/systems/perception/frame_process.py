"""``FrameProcess`` — the rgbd perception's per-frame work (the depth image's point cloud and the
parts' fit, ``PartPoseEstimator.fit_frame``: 3–10 ms a frame) in a process of its own, for a
control loop that must answer every 1 ms tick (``ptint drive``).

In the one-process run the estimator fits frame k in its update at t_k = k · (1 / rate) and its
sample becomes visible at t_k + latency: nothing reads it before then. With
``PerceptionConfig.fits_elsewhere`` the estimator's event at t_k only marks the time (the
simulator ends a step there, as before), and this object does the rest: ``submit`` hands a frame
to the worker process as soon as it arrives (with the status of the tick whose period holds t_k) —
its LCM message's bytes as received, decoded in the worker by the function ``start`` names (the
loop reads only its time stamp), or an image's pixels; ``take_due(context, t)``, called before the
loop advances its diagram to a tick t, writes every frame whose sample is visible by t (t_k +
latency ≤ t) into the estimator's state (``PartPoseEstimator.write_frame``: the same association,
buffer and memory as its own update), oldest first — waiting for a fit that is not back yet. A
sample written before t_k + latency is not visible before then, so every output of the estimator,
at every time, is what the one-process run's is: the loop's result does not depend on when a fit
comes back (lockstep: the same as with the fit in the loop, to the last bit), only its timing
does. In real time the fit has the latency to come back (33 ms in the bundled camera picks); the
loop waits only for one that has not.

A process, not a thread: a fit is Python (numpy, scipy) and would hold Python's interpreter lock
for most of its milliseconds, and pydrake's ``DrakeLcm.HandleSubscriptions`` keeps that lock while
it waits for a message (measured: a spinning thread ran 3 % as fast during the wait as during a
sleep), so a thread would both starve and delay the loop. The worker is a fresh interpreter
(``python -m`` this module, one end of a socket pair: no copy of the parent's LCM sockets, threads
or real-time priority), builds the perception (``MakeRgbdPerception``) from the pickled
``PerceptionConfig`` and answers each image with its fits (``multiprocessing``'s ``Connection``
framing); ``start`` returns once it is ready, ``close`` ends it.
"""

from __future__ import annotations

import dataclasses
import importlib
import math
import os
import socket
import subprocess
import sys
import time
from collections import deque
from multiprocessing.connection import Connection
from pathlib import Path
from typing import Optional

import numpy as np

from ptint_drake.systems.perception.part_pose_estimator import (TIME_TOL, PartPoseEstimator,
                                                                 PerceptionConfig)

READY_TIMEOUT = 120.0  # s: the worker's start (a fresh interpreter imports pydrake)
SEND_BUFFER = 4 << 20  # bytes: the socket's send buffer (a frame of 424 × 240 floats is 407 kB)


class FrameError(Exception):
    """A frame the worker could not read (the message is the one-line reason)."""


def _decoder(name: Optional[str]):
    """The function ``module:function`` that reads a frame's message bytes into (utime, image)."""
    if name is None:
        return None
    module, function = name.split(":")
    return getattr(importlib.import_module(module), function)


def _serve(conn) -> None:
    """The worker process: build the perception from the first message (a ``PerceptionConfig``
    and the name of a message decoder, or None), then fit every image received until None: an
    image's pixels, or a frame's message bytes (decoded here)."""
    from pydrake.systems.sensors import ImageDepth32F  # noqa: PLC0415

    from ptint_drake.systems.perception.part_pose_estimator import MakeRgbdPerception  # noqa: PLC0415

    config, decoder = conn.recv()
    decode = _decoder(decoder)
    perception, estimator = MakeRgbdPerception(dataclasses.replace(config, fits_elsewhere=False))
    context = perception.CreateDefaultContext()
    cloud_system = perception.GetSubsystemByName("depth_to_cloud")
    cloud_port = cloud_system.point_cloud_output_port()
    cloud_context = cloud_system.GetMyContextFromRoot(context)
    conn.send("ready")
    while True:
        job = conn.recv()
        if job is None:
            return
        k, width, height = job
        data = conn.recv_bytes()
        start = time.perf_counter()
        if width is None:  # a frame's message as received
            try:
                _, image = decode(data)
            except ValueError as exc:
                conn.send((k, f"camera frame rejected: {exc}", None))
                continue
        else:
            image = ImageDepth32F(width, height)
            image.mutable_data[:, :, 0] = np.frombuffer(data, dtype=np.float32).reshape(height, width)
        perception.get_input_port().FixValue(context, image)
        cloud = cloud_port.Eval(cloud_context)
        rendered = time.perf_counter()
        fits = estimator.fit_frame(cloud)
        conn.send((k, fits, {"cloud_s": rendered - start, "fit_s": time.perf_counter() - rendered}))


class FrameProcess:
    """The perception's fits in a worker process (module docstring), for ``estimator`` (built with
    ``fits_elsewhere``) in a loop whose ticks are ``tick`` s apart."""

    def __init__(self, estimator: PartPoseEstimator, config: PerceptionConfig, tick: float):
        self._estimator, self._config, self._tick = estimator, config, tick
        self._period = 1.0 / config.rate_hz  # the estimator's: its events at k · period
        self._jobs: deque = deque()  # (k, t_k) submitted, not yet written
        self._results: dict = {}  # k → (fits, timing) back from the worker
        self._conn = self._process = None
        self.waits: list = []  # s the loop waited for each frame written
        self.fit_s: list = []  # s of each fit in the worker (cloud and fit)

    def start(self, decoder: Optional[str] = None) -> None:
        """Start the worker and wait until it is ready (``READY_TIMEOUT``); ``decoder``:
        ``module:function`` reading a frame's message bytes into (utime, ImageDepth32F)."""
        if self._process is not None:
            return
        ours, theirs = socket.socketpair()
        ours.setsockopt(socket.SOL_SOCKET, socket.SO_SNDBUF, SEND_BUFFER)  # a frame never blocks
        # this package first, whatever the caller's sys.path; and not the working folder before it
        # (``-m`` puts it first unless PYTHONSAFEPATH, Python >= 3.11): inside a source tree that
        # would be the tree's package, and its numba cache, rather than this one
        env = dict(os.environ, PYTHONSAFEPATH="1")
        env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).resolve().parents[3]),
                                             env.get("PYTHONPATH", "")])
        self._process = subprocess.Popen([sys.executable, "-m", __name__, str(theirs.fileno())],
                                         pass_fds=(theirs.fileno(),), env=env)
        theirs.close()
        self._conn = Connection(ours.detach())
        self._conn.send((self._config, decoder))
        if not self._conn.poll(READY_TIMEOUT) or self._conn.recv() != "ready":
            raise RuntimeError(f"the perception's worker process did not start within {READY_TIMEOUT:g} s")

    def frame_index(self, t: float, handshake: bool = False) -> int:
        """k of the frame that comes with the status of the tick at ``t``: the one in (t, t + tick]
        (the hand-shake's: the one at t = 0)."""
        if handshake:
            return 0
        return math.floor((t + self._tick) / self._period + TIME_TOL)

    def submit(self, t: float, image, handshake: bool = False) -> None:
        """Hand the frame that came with the status of ``t`` to the worker: an ``ImageDepth32F``,
        or its message's bytes as received (read there by ``start``'s decoder)."""
        k = self.frame_index(t, handshake)
        if any(j == k for j, _ in self._jobs):
            return  # (a status's re-send brings its frame again)
        if isinstance(image, (bytes, bytearray)):
            self._conn.send((k, None, None))
            self._conn.send_bytes(image)
        else:
            self._conn.send((k, image.width(), image.height()))
            self._conn.send_bytes(np.ascontiguousarray(np.asarray(image.data, dtype=np.float32)[:, :, 0]))
        self._jobs.append((k, k * self._period))

    def _collect(self, wait: Optional[float]) -> None:
        """Results back from the worker (``wait``: s to block for one; None: none)."""
        while self._conn.poll(wait if wait is not None else 0):
            try:
                k, fits, timing = self._conn.recv()
            except EOFError:  # the worker is gone (``take_due`` says so)
                return
            self._results[k] = (fits, timing)
            if timing is not None:
                self.fit_s.append(timing["cloud_s"] + timing["fit_s"])
            wait = None

    def take_due(self, root_context, t: float) -> None:
        """Write every submitted frame visible by ``t`` into the estimator's state, oldest first
        (waiting for a fit not back yet)."""
        latency = self._config.latency
        while self._jobs and self._jobs[0][1] + latency <= t + TIME_TOL:
            k, t_k = self._jobs.popleft()
            start = time.perf_counter()
            while k not in self._results:
                if self._process.poll() is not None:
                    code = self._process.returncode
                    raise FrameError(f"the perception's process ended (exit code {code})")
                self._collect(0.5)
            self.waits.append(time.perf_counter() - start)
            fits, timing = self._results.pop(k)
            if timing is None:  # the worker could not read the frame
                raise FrameError(fits)
            context = self._estimator.GetMyMutableContextFromRoot(root_context)
            self._estimator.write_frame(context, t_k, fits, timing)
        self._collect(None)

    def prefetch(self) -> None:
        """Wait until every frame submitted is back (e.g. before the loop's first real-time tick)."""
        while any(k not in self._results for k, _ in self._jobs):
            self._collect(0.5)

    def close(self) -> Optional[dict]:
        """End the worker; {process, fit_ms, wait_ms}: where the fits ran, how long each took and
        how long the loop waited for each (median, p99, max, count), or None when not started."""
        if self._process is None:
            return None
        try:
            self._conn.send(None)
        except (BrokenPipeError, OSError):
            pass
        try:
            self._process.wait(timeout=5.0)
        except subprocess.TimeoutExpired:
            self._process.kill()
        self._conn.close()
        self._process = None
        return {"process": "own", "fit_ms": _spread(self.fit_s), "wait_ms": _spread(self.waits)}


def _spread(values: list) -> Optional[dict]:
    """Median, p99, max (ms) and count of ``values`` (s); None when empty."""
    if not values:
        return None
    a = 1e3 * np.asarray(values, dtype=float)
    return {"median": float(np.median(a)), "p99": float(np.percentile(a, 99)), "max": float(a.max()),
            "count": int(a.size)}


if __name__ == "__main__":  # the worker: ``python -m ptint_drake.systems.perception.frame_process FD``
    _serve(Connection(int(sys.argv[1])))
