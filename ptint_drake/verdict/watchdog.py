"""The divergence watchdog: a simulator monitor that stops a run going nowhere, and progress.

It reads the plant state and the true target only, like the metrics.
"""

from __future__ import annotations

import time

import numpy as np
from pydrake.systems.framework import EventStatus

_SUCCEEDED = EventStatus.Succeeded()


class Watchdog:
    """Simulator monitor: progress reports and the divergence checks.

    Every 10th step (a Python call per step is all the other steps cost) the
    plant state must be finite and every joint speed within ``limits.max_joint_speed``;
    every 50th step |e| (against the true target, one extra evaluation of the
    interceptor) within ``limits.max_error`` of its value at the active segment's start
    (``segment_started``, called at each segment's start: the runner stops there exactly) — it
    judges growth, not size, so a segment that starts far away (a thrown object 1.4 m off) is
    judged on where it goes.  A violation
    ends the simulation (ReachedTermination) with a message saying when and which
    quantity.  An integrator failure is caught by ``simulate`` the same way.
    """

    def __init__(self, *, scenario, diagram, plant, position_of, true_target, progress=None, schedule=None):
        """``position_of(context)``: the gripper point from the plant state in the root
        context; ``true_target(t)``: the true active object's position."""
        self.failure = None
        self._diagram = diagram
        self._scenario = scenario
        self._nq = plant.num_positions()
        self._state_port = plant.get_state_output_port()
        self._plant_context_of = plant.GetMyContextFromRoot
        self._position_of = position_of
        self._true_target = true_target
        self._progress = progress
        self._last = 0.0
        self._count = 0
        self._reference = 0.0  # |e| at the active segment's start (m)

    def segment_started(self, error: float) -> None:
        """|e| at the start of the segment that begins now: the reference of the error check."""
        self._reference = float(error)

    def __call__(self, context):
        self._count += 1
        if self._count % 10:
            return _SUCCEEDED
        t = context.get_time()
        qv = self._state_port.Eval(self._plant_context_of(context))
        limits = self._scenario.limits
        if not np.all(np.isfinite(qv)):
            return self._fail(t, "the plant state is not finite")
        speed = float(np.max(np.abs(qv[self._nq:]))) if len(qv) > self._nq else 0.0
        if speed > limits.max_joint_speed:
            return self._fail(t, f"joint speed {speed:.3g} exceeds limits.max_joint_speed "
                                 f"= {limits.max_joint_speed:g}")
        if self._count % 50:
            return _SUCCEEDED
        err = float(np.linalg.norm(self._position_of(context) - self._true_target(t)))
        if not np.isfinite(err) or err > self._reference + limits.max_error:
            return self._fail(t, f"interception error |e| = {err:.3g} m exceeds its value at the segment's "
                                 f"start ({self._reference:.3g} m) by more than limits.max_error = "
                                 f"{limits.max_error:g} m")
        return self._report(t)

    def _report(self, t):
        if self._progress is not None:
            now = time.perf_counter()
            if now - self._last > 0.2:
                self._last = now
                self._progress(t, self._scenario.duration, self._count)
        return _SUCCEEDED

    def _fail(self, t, what):
        self.failure = {"time": t, "message": f"diverged at t = {t:.4f} s: {what}"}
        return EventStatus.ReachedTermination(self._diagram, self.failure["message"])

    def integration_failed(self, t, exc):
        detail = " ".join(str(exc).split())[:300]
        self.failure = {"time": t, "message": f"integration failed at t = {t:.4f} s: {detail}"}

    def controller_failed(self, t, controller: str, exc: BaseException):
        """A user's controller (plugin) raised while simulating: the run fails, the program goes on."""
        detail = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
        self.failure = {"time": t, "message": f"controller {controller} raised at t = {t:.4f} s: {detail}"}
