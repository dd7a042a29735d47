"""Pieces shared by the baseline controllers (``pd``, ``smc``, ``ct_quintic``).

Every baseline has the same ports: inputs ``state`` ([q; v], nq + nv) and ``target``
([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs ``u`` (actuation, u = Bᵀ τ), ``tau`` (nv, velocity
order) and ``telemetry`` whose slots are named by the system's ``layout``.
Segment starts are Drake events (``schedule.DeclareSegmentStartEvents``): one
initialization event and one one-shot timed event per later start, so the integrator stops
exactly at each switch.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from ptint_drake.systems.schedule import Schedule
from ptint_drake.systems.signals import Slots


def make_layout(sizes: Iterable[tuple[str, int]]) -> dict:
    """name -> slice of a telemetry vector made of consecutive slots of the given sizes."""
    return Slots(*sizes).slices()


def layout_size(layout: dict) -> int:
    """The length of a telemetry vector with this ``layout``."""
    return max(s.stop for s in layout.values())


def segment_index(schedule: Schedule, t: float) -> int:
    """The active segment at t; before the first start, the first segment (it is what comes)."""
    return max(schedule.active(t), 0)


def DeclareControllerOutputs(system, plant, layout: dict, evaluate: Callable, deps: set) -> None:
    """Declare ``u`` (Bᵀ τ), ``tau`` and ``telemetry`` on ``system``; ``evaluate(context)`` returns
    a vector whose first ``layout_size(layout)`` values are the telemetry (with a ``tau`` slot)."""
    BT = plant.MakeActuationMatrix().T
    tau, size = layout["tau"], layout_size(layout)
    system.DeclareVectorOutputPort(
        "u", BT.shape[0], lambda c, o: o.SetFromVector(BT @ evaluate(c)[tau]),
        prerequisites_of_calc=deps)
    system.DeclareVectorOutputPort(
        "tau", plant.num_velocities(), lambda c, o: o.SetFromVector(evaluate(c)[tau]),
        prerequisites_of_calc=deps)
    system.DeclareVectorOutputPort(
        "telemetry", size, lambda c, o: o.SetFromVector(evaluate(c)[:size]),
        prerequisites_of_calc=deps)
