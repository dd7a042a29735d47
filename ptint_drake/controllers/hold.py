"""Sampled control: the drive's zero-order hold between any controller and the station.

With ``controller.control_period`` T > 0, ``AddActuationHold`` puts one Drake
``ZeroOrderHold`` (named ``control_hold``, period T, first sample at t = 0) between the
slot's ``actuation`` and the station's: every controller of the registry and every plugin
is then run as a periodic discrete system from the plant's side.  At t_k = kT the hold
samples the controller's output, computed from the plant state x(t_k) and the target at
t_k, and the station receives that torque unchanged until t_{k+1}, as from a digital drive
(no computation delay within the sample).  The controller's own internal state (σ of the
sliding surface, the PID's integral) is still integrated with the loop; only what reaches the
plant is sampled.

On a discrete plant (``multibody.time_step`` h > 0) the plant and the hold update together
at the sample instants, and Drake's simultaneous discrete updates all read the state before
the update: the plant's step at t_k then applies the torque the hold took at t_{k−1}, one
period of delay, as a drive that applies each command at the next tick.

=================  ======  ================================================
port (hold)        size    meaning
=================  ======  ================================================
input              nu      the controller's actuation, in actuator order
output             nu      the held actuation, into the station's ``actuation``
=================  ======  ================================================

``held_telemetry`` makes the run's ``tau`` telemetry the held torque (what the plant got),
logged at every integrator step like the rest.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import DiagramBuilder, InputPort
from pydrake.systems.primitives import ZeroOrderHold

from ptint_drake.controllers.slot import ControllerHandles

HOLD_NAME = "control_hold"


def AddActuationHold(builder: DiagramBuilder, actuation: InputPort, period: float) -> ZeroOrderHold:
    """Add the hold of period ``period`` (s) in front of ``actuation`` (the station's input) and
    connect its output there; the controller connects to the hold's input instead."""
    hold = builder.AddNamedSystem(HOLD_NAME, ZeroOrderHold(period, actuation.size()))
    builder.Connect(hold.get_output_port(), actuation)
    return hold


def held_telemetry(handles: ControllerHandles, hold: ZeroOrderHold, B: np.ndarray) -> ControllerHandles:
    """``handles`` with the hold's output logged and its ``tau`` (N·m or N per generalized
    velocity, ``B`` the plant's actuation matrix) replaced by the held torque; the value logged
    at a sample instant is the one held up to it."""
    inner = handles.telemetry

    def telemetry(logs: dict) -> dict:
        out = inner(logs)
        out["tau"] = logs[HOLD_NAME] @ B.T
        return out

    handles.log_ports = dict(handles.log_ports) | {HOLD_NAME: hold.get_output_port()}
    handles.telemetry = telemetry
    handles.notes = list(handles.notes) + [
        f"sampled control: period {hold.period() * 1e3:g} ms, zero-order hold on the actuation"]
    return handles
