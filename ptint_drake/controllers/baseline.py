"""Pieces shared by the baseline controllers (``pd``, ``smc``, ``ct_quintic``).

Every baseline has the same ports: inputs ``state`` ([q; v], nq + nv) and ``target``
([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs ``u`` (actuation, u = Bᵀ τ), ``tau`` (nv, velocity
order) and ``telemetry`` whose slots are named by the system's ``layout``.
Segment starts are Drake events (``schedule.DeclareSegmentStartEvents``): one
initialization event and one one-shot timed event per later start, so the integrator stops
exactly at each switch.

``TaskSpaceBaseline`` is the part of the model-free baselines (``pd``, ``smc``) that is the
same in both: the ports, a continuous state of 3 (PD: ∫e, SMC: σ), the per-segment values
stored at each segment start with the segment's index, and the task-space error

    e = x − x_r,  ė = ẋ − ẋ_r,   x = f(q), ẋ = J(q) q̇   (m, m/s)

read at the start of each evaluation.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import NamedTuple

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.task.signals import TARGET, TARGET_PORT_SIZE, Slots


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


class TaskSpaceReading(NamedTuple):
    """What a model-free baseline reads at the start of an evaluation (``TaskSpaceBaseline.read``)."""

    x: np.ndarray  # frame position f(q) (m)
    xdot: np.ndarray  # frame velocity J(q) q̇ (m/s)
    J: np.ndarray  # translational Jacobian (3 × nv)
    e: np.ndarray  # x − x_r (m)
    edot: np.ndarray  # ẋ − ẋ_r (m/s)
    memory: np.ndarray  # the continuous state (a copy): ∫e or σ
    segment: np.ndarray  # the discrete state [segment, values…] (read-only view)


class TaskSpaceBaseline(LeafSystem):
    """Base of the model-free baselines (``pd.PDController``, ``smc.FirstOrderSMC``).

    Inputs ``state`` (nq + nv), ``target`` ([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs
    ``u``, ``tau``, ``telemetry`` (``DeclareControllerOutputs``) from one cache entry ``name`` of
    ``_calc(context)`` (the telemetry of ``layout``, then ``extra`` values).  State: a
    continuous 3-vector whose derivative is the ``derivative`` slice of that cache entry, and a
    discrete [segment, values…] (``values`` long after the index, −1 and zeros until the
    first start).  At every segment start (``DeclareSegmentStartEvents``) the active segment i
    is stored with ``_segment_values(tf_i)`` and, with ``reset``, the continuous state is zeroed.
    """

    def __init__(self, *, plant, frame, schedule: Schedule, layout: dict, name: str, values: int,
                 reset: bool, derivative: slice, extra: int = 0):
        super().__init__()
        self._schedule = schedule
        self._reset = reset
        self._derivative = derivative
        self._nq, self._nv = plant.num_positions(), plant.num_velocities()
        self._kinematics = FrameKinematics(plant, frame)
        self.layout = layout
        self._state_in = self.DeclareVectorInputPort("state", self._nq + self._nv)
        self._target_in = self.DeclareVectorInputPort("target", TARGET_PORT_SIZE)
        self._memory_index = self.DeclareContinuousState(3)
        self._segment_index = self.DeclareDiscreteState(np.array([-1.0, *[0.0] * values]))
        DeclareSegmentStartEvents(self, schedule, self._on_segment_start)
        deps = {self.time_ticket(), self.xc_ticket(), self.xd_ticket(),
                self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, name, layout_size(layout) + extra, self._calc, deps)
        DeclareControllerOutputs(self, plant, layout, self._eval, deps)

    def _segment_values(self, tf: float) -> list:
        """The values stored for a segment of duration tf (s)."""
        raise NotImplementedError

    def _calc(self, context) -> np.ndarray:
        """The cache entry: the telemetry, then ``extra`` values."""
        raise NotImplementedError

    def _on_segment_start(self, context, state) -> None:
        i = segment_index(self._schedule, context.get_time())
        state.get_mutable_discrete_state(self._segment_index).SetFromVector(
            [i, *self._segment_values(self._schedule[i].tf)])
        if self._reset:
            state.get_mutable_continuous_state().get_mutable_vector().SetZero()

    def read(self, context) -> TaskSpaceReading:
        """The frame's x, ẋ, J at the ``state`` input, e and ė against ``target``, the
        continuous state and the stored segment values."""
        qv = self._state_in.Eval(context)
        target = self._target_in.Eval(context)
        x, xdot, J = self._kinematics.compute(qv[: self._nq], qv[self._nq:])
        e, edot = x - target[TARGET.x], xdot - target[TARGET.xdot]
        return TaskSpaceReading(x, xdot, J, e, edot, context.get_continuous_state_vector().CopyToVector(),
                                context.get_discrete_state(self._segment_index).value())

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[self._derivative])
