"""The whole interceptor in one LeafSystem: the fast path for simulation.

``PrescribedTimeInterceptor`` computes exactly what the five blocks wired by
``AddPrescribedTimeInterceptor(fused=False)`` compute — it calls the same
functions (``tbg_state``, ``active_target_values``, ``FrameKinematics``,
``SurfaceLaw``, ``smc_torque``) — but as one cache entry per context, so each
derivative evaluation crosses from C++ into Python three times instead of about
sixteen.  Its ``telemetry`` port carries every intermediate signal (layout in
``telemetry_layout``).  Logging it at every step would cost one more full
evaluation per step, so a run logs only states (the plant's, and ``sigma`` and
``captured`` here, all C++ state ports) and ``telemetry_at`` recomputes the
telemetry of each logged sample afterwards — the same function on the same
state, so the values are identical.

Model-free like the blocks: it reads the plant's state and kinematics only.
"""

from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.cache import DeclareVectorCache
from ptint_drake.systems.controller import null_space_terms, null_space_torque, smc_torque
from ptint_drake.systems.gains import ControllerGains
from ptint_drake.systems.kinematics import FrameKinematics
from ptint_drake.systems.schedule import Schedule
from ptint_drake.systems.orientation import active_rotation_values
from ptint_drake.systems.signals import (
    TARGET,
    TARGET_PORT,
    TARGET_PORT_SIZE,
    TBG,
    TBG_OUT,
    TARGET_ROTATION_SIZE,
    Slots,
    surface_slots,
)
from ptint_drake.systems.sliding_surface import DeclareSegmentCapture, SurfaceLaw
from ptint_drake.systems.targets import active_target_values
from ptint_drake.systems.task import TASK_DIM, position_error, task_error, task_jacobian
from ptint_drake.systems.tbg import tbg_state


def telemetry_layout(nv: int, task: str = "position") -> dict:
    """name -> slice of the ``telemetry`` vector (n = the task's dimension, 3 or 6; a task with
    orientation adds the tool's ``R``, ``omega`` and the ``target_rotation`` it saw)."""
    n = TASK_DIM[task]
    extra = [] if task == "position" else [("R", 9), ("omega", 3), ("target_rotation", TARGET_ROTATION_SIZE)]
    return Slots(("x", 3), ("xdot", 3), ("x_r", 3), ("xdot_r", 3), ("xddot_r", 3), ("xi", 4),
                 ("alpha", 1), ("s_x", n), ("e", n), ("edot", n), ("s", n), ("s_d", n),
                 ("sigma", n), ("tau", nv), *extra).slices()


class PrescribedTimeInterceptor(LeafSystem):
    """Input ``state`` ([q; v] of the plant); outputs ``u`` (actuation), ``tau`` (joint
    torques) and ``telemetry``.  State: σ (continuous, n), [index, s(t0)] (discrete), n the
    dimension of ``gains.task`` (``systems.task``: 3 for ``position``, 6 with orientation).

    With ``targets`` (one per segment, ``evaluate(t)`` → [x, ẋ, ẍ, …]) the target is
    computed inside (the fast path for analytic targets); with ``targets=None`` the
    system has an input port ``target`` ([x_r, ẋ_r, ẍ_r] of the active segment,
    e.g. a Kalman filter's estimate) and holds no target object at all; with an orientation
    task it then has an input ``target_rotation`` too ([R_r, ω_r, ω̇_r], 15).
    """

    def __init__(self, *, plant, frame, schedule: Schedule, gains: ControllerGains,
                 targets: Optional[Sequence] = None, posture: Optional[np.ndarray] = None):
        super().__init__()
        if targets is not None and len(targets) != len(schedule):
            raise ValueError(f"targets: one target per segment is needed, got {len(targets)} "
                             f"for {len(schedule)} segments")
        nq, nv = plant.num_positions(), plant.num_velocities()
        self._nq, self._nv = nq, nv
        self._schedule = schedule
        self._targets = None if targets is None else tuple(targets)
        self._tbg_args = (gains.epsilon, gains.delta, gains.alpha_hold)
        self._kinematics = FrameKinematics(plant, frame)
        self._task, self._rot_scale = gains.task, float(gains.rot_scale)
        self._n = n = TASK_DIM[gains.task]
        self._law = SurfaceLaw(gains.Lambda, gains.k, gains.switching, gains.phi,
                               gains.sigma_policy, gains.k_hold, n)
        self._K = np.broadcast_to(np.asarray(gains.K, dtype=float), (nv,)).copy()
        self._K_floats = tuple(self._K.tolist())
        self._damping = float(gains.pinv_damping)
        self._null_space = null_space_terms(gains, plant, posture)  # redundant arms only
        self._BT = plant.MakeActuationMatrix().T
        self.layout = telemetry_layout(nv, gains.task)
        size = max(part.stop for part in self.layout.values())

        self._state_in = self.DeclareVectorInputPort("state", nq + nv)
        self._target_in = None if targets is not None else self.DeclareVectorInputPort(
            "target", TARGET_PORT_SIZE)
        self._rotation_in = None if targets is not None or gains.task == "position" else \
            self.DeclareVectorInputPort("target_rotation", TARGET_ROTATION_SIZE)
        # the cache holds the telemetry, then the active segment (5), then σ̇ (n)
        self._segment = slice(size, size + 5)
        self._sigma_dot = slice(size + 5, size + 5 + n)
        self._parts = surface_slots(n)
        sigma_index, capture_index = DeclareSegmentCapture(
            self, schedule, self._law,
            lambda c: (self._eval(c)[self._segment], self._eval(c)[self.layout["s"]]))
        self.DeclareStateOutputPort("sigma", sigma_index)
        self.DeclareStateOutputPort("captured", capture_index)
        self._capture_index = capture_index
        deps = {self.time_ticket(), self.xc_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        self._eval = DeclareVectorCache(self, "interceptor", size + 5 + n, self._calc, deps)
        tau = self.layout["tau"]
        if self._BT.shape[0] == nv and np.array_equal(self._BT, np.eye(nv)):
            calc_u = lambda c, o: o.SetFromVector(self._eval(c)[tau])  # noqa: E731
        else:
            calc_u = lambda c, o: o.SetFromVector(self._BT @ self._eval(c)[tau])  # noqa: E731
        self.DeclareVectorOutputPort("u", self._BT.shape[0], calc_u, prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("tau", nv, lambda c, o: o.SetFromVector(self._eval(c)[tau]),
                                     prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("telemetry", size,
                                     lambda c, o: o.SetFromVector(self._eval(c)[:size]),
                                     prerequisites_of_calc=deps)

    @property
    def has_target_input(self) -> bool:
        return self._target_in is not None

    @property
    def has_rotation_input(self) -> bool:
        return self._rotation_in is not None

    def _calc(self, context) -> np.ndarray:
        # the cheapest reads of the context (views and single values, no copies): ~3 µs less
        # per evaluation than CopyToVector and Eval
        sigma = context.get_continuous_state_vector()
        rotation = None if self._rotation_in is None else self._rotation_in.Eval(context).tolist()
        return np.array(self._row(
            context.get_time(), self._state_in.EvalBasicVector(context).value(),
            [sigma.GetAtIndex(i) for i in range(self._n)],
            context.get_discrete_state(self._capture_index).value().tolist(),
            None if self._target_in is None else self._target_in.Eval(context).tolist(), rotation))

    def _row(self, t: float, qv: np.ndarray, sigma: list, captured: list,
             target: Optional[list], rotation: Optional[list] = None) -> list:
        """The cache vector (telemetry, active segment, σ̇) as a list of plain floats, from the
        time, the plant state [q; v] (an array), σ, [index, s(t0)] and the ``target`` (and
        ``target_rotation``) inputs' values (None: the system's own targets)."""
        nq = self._nq
        if target is None:
            target = active_target_values(self._schedule, self._targets, t)
        if self._task == "position":
            x, xdot, J = self._kinematics.compute(qv[:nq], qv[nq:])
            x, xdot, J = x.tolist(), xdot.tolist(), J.tolist()
            e, edot = position_error(x, xdot, target[TARGET.x], target[TARGET.xdot])
            extra = []
        else:
            x, xdot, R, omega, J_v, J_w = self._kinematics.compute_pose(qv[:nq], qv[nq:])
            x, xdot, R, omega = x.tolist(), xdot.tolist(), R.ravel().tolist(), omega.tolist()
            J = task_jacobian(J_v, J_w, self._rot_scale)
            if rotation is None:
                rotation = active_rotation_values(self._schedule, self._targets, t)
            e, edot = task_error(self._task, self._rot_scale, x, xdot, target[TARGET.x],
                                 target[TARGET.xdot], R, omega, rotation)
            extra = R + omega + list(rotation)
        tbg = tbg_state(self._schedule, t, *self._tbg_args)
        parts = self._law.values(t, e, edot, tbg[TBG.alpha], tbg[TBG.segment], captured, sigma)
        slots = self._parts
        tau = smc_torque(self._K_floats, J, parts[slots.s_x], self._damping)
        if self._null_space is not None:  # redundant arms, optional (off by default)
            D, rate, q_start = self._null_space
            extra_tau = null_space_torque(np.array(J), qv[:nq], qv[nq:], q_start, D, rate)
            tau = (np.array(tau) + extra_tau).tolist()
        return (x + xdot + target[TARGET_PORT] + tbg[TBG_OUT] + parts[slots.out] + sigma + tau + extra
                + tbg[TBG.segment] + parts[slots.sigma_dot])

    def telemetry_at(self, t: np.ndarray, plant_state: np.ndarray, sigma: np.ndarray,
                     captured: np.ndarray, target: Optional[np.ndarray] = None,
                     rotation: Optional[np.ndarray] = None) -> np.ndarray:
        """Telemetry rows for logged samples (time, plant state, σ, [index, s(t0)], and the
        ``target`` / ``target_rotation`` inputs' values when the system has those ports).

        The same ``_row`` as a context's cache entry, called directly on the logged values
        (no context, no cache entry, no crossing into Drake but the kinematics).
        """
        size = self._segment.start
        n = len(t)
        if n == 0:
            return np.empty((0, size))
        targets = [None] * n if self._target_in is None else np.asarray(target).tolist()
        rotations = [None] * n if self._rotation_in is None else np.asarray(rotation).tolist()
        row = self._row
        rows = np.array([row(tk, qv, sg, cap, tg, rt) for tk, qv, sg, cap, tg, rt in zip(
            np.asarray(t, dtype=float).tolist(), np.asarray(plant_state, dtype=float),
            np.asarray(sigma, dtype=float).tolist(), np.asarray(captured, dtype=float).tolist(),
            targets, rotations)])
        return rows[:, :size]

    def DoCalcTimeDerivatives(self, context, derivatives):
        derivatives.get_mutable_vector().SetFromVector(self._eval(context)[self._sigma_dot])
