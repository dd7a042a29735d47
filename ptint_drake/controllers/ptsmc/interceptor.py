"""The whole interceptor as one system: the fast path for simulation.

``PrescribedTimeInterceptor`` computes what the five blocks wired by
``AddPrescribedTimeInterceptor(fused=False)`` compute, with the same compiled kernels
(``interceptor_row``: the TBG, the surface law, the torque and, for the position task, the
kinematic chain and the target, in one call).  It is a small Diagram:

    state ─> Multiplexer ─loop─> InterceptorLaw ─[τ; σ̇]─> Demultiplexer ─τ─> (Bᵀ) ─> u
    (targets)   ↑ σ, captured                                      └σ̇─> Integrator (σ) ─┐
                └──────────────────────────────────────────────────────────────────────┘

so each derivative evaluation enters Python once (the law's one output; Drake's Integrator
holds σ and Drake's cache hands the same output to the plant and to the integrator) and reads
one input: the Multiplexer gathers the plant state, σ, the law's own ``captured`` state (a state
output: no feedthrough, no algebraic loop) and the ``target`` and ``target_rotation`` inputs into
one vector, which the compiled paths (``interceptor_row.position_output``, and ``pose_output`` for
the pose and top-down tasks) take as it is.  Its
``telemetry`` port carries every intermediate signal (layout in ``telemetry_layout``).  A run
logs only C++ ports (the plant's state, ``sigma`` and ``captured``) and ``telemetry_at``
recomputes the telemetry of each logged sample afterwards — the same kernel on the same state,
so the values are identical.

``sigma_policy = "reset"``: the Integrator keeps integrating; the capture at a segment start
stores its value σ0 beside s(t0), and the law uses σ − σ0.

Model-free like the blocks: it reads the plant's state and kinematics only.
"""

from __future__ import annotations

from functools import cached_property
from typing import Optional, Sequence

import numpy as np
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import Demultiplexer, Integrator, MatrixGain, Multiplexer

from ptint_drake.controllers.ptsmc.gains import ControllerGains
from ptint_drake.controllers.ptsmc.interceptor_row import (pack_chain, pack_gains, pack_pose, pack_position,
                                                           pose_output, pose_row, pose_rows, position_output,
                                                           position_rows, task_row)
from ptint_drake.controllers.ptsmc.jit_notice import compile_notice
from ptint_drake.controllers.ptsmc.law import null_space_terms, null_space_torque
from ptint_drake.controllers.ptsmc.sliding_surface import SurfaceLaw
from ptint_drake.systems.task.error import TASK_DIM, TASKS
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.orientation import ROTATION_WIDTH, active_rotation_values, compiled_rotations
from ptint_drake.systems.task.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.task.signals import (IDENTITY_ROTATION, TARGET_PORT, TARGET_PORT_SIZE,
                                              TARGET_ROTATION_SIZE, Slots)
from ptint_drake.systems.task.targets import active_target_values, compiled_targets

_NO_TARGET = np.empty(0)
_NO_ROTATIONS = np.zeros((1, ROTATION_WIDTH))


def telemetry_layout(nv: int, task: str = "position") -> dict:
    """name -> slice of the ``telemetry`` vector (n = the task's dimension, 3 or 6; a task with
    orientation adds the tool's ``R``, ``omega`` and the ``target_rotation`` it saw)."""
    n = TASK_DIM[task]
    extra = [] if task == "position" else [("R", 9), ("omega", 3), ("target_rotation", TARGET_ROTATION_SIZE)]
    return Slots(("x", 3), ("xdot", 3), ("x_r", 3), ("xdot_r", 3), ("xddot_r", 3), ("xi", 4),
                 ("alpha", 1), ("s_x", n), ("e", n), ("edot", n), ("s", n), ("s_d", n),
                 ("sigma", n), ("tau", nv), *extra).slices()


def loop_sizes(nq: int, nv: int, n: int, target_input: bool, rotation_input: bool = False) -> list:
    """The parts of ``InterceptorLaw``'s ``loop`` input: [q; v] (nq + nv), σ (n), captured
    [index, s(t0), σ0] (1 + 2n), with a target input [x_r, ẋ_r, ẍ_r] (``TARGET_PORT_SIZE``) and
    with a rotation input too [R_r, ω_r, ω̇_r] (``TARGET_ROTATION_SIZE``)."""
    return [nq + nv, n, 1 + 2 * n] + ([TARGET_PORT_SIZE] if target_input else []) + \
        ([TARGET_ROTATION_SIZE] if rotation_input else [])


class InterceptorLaw(LeafSystem):
    """Input ``loop`` ([q; v; σ; captured; target; target_rotation], ``loop_sizes``: the plant
    state, the Integrator's σ (n), the ``captured`` output fed back and, without target objects,
    the target estimate and, with an orientation task, the target's rotation); outputs
    ``tau_sigma_dot`` ([τ; σ̇], nv + n), ``telemetry`` and ``captured`` (its discrete state
    [index, s(t0), σ0], 1 + 2n).  See ``PrescribedTimeInterceptor``."""

    def __init__(self, *, plant, frame, schedule: Schedule, gains: ControllerGains,
                 targets: Optional[Sequence] = None, posture: Optional[np.ndarray] = None):
        super().__init__()
        nq, nv = plant.num_positions(), plant.num_velocities()
        self._nq, self._nv, self._schedule = nq, nv, schedule
        self._targets = None if targets is None else tuple(targets)
        self._task, self._rot_scale = gains.task, float(gains.rot_scale)
        self._n = n = TASK_DIM[gains.task]
        self._law = SurfaceLaw(gains.Lambda, gains.k, gains.switching, gains.phi,
                               gains.sigma_policy, gains.k_hold, n)  # validates the gains
        K = np.broadcast_to(np.asarray(gains.K, dtype=float), (nv,)).copy()
        self._gains = pack_gains(gains, n, K)
        self._kinematics = FrameKinematics(plant, frame)
        self._null_space = null_space_terms(gains, plant, posture)  # redundant arms only
        compiled = None if self._targets is None else compiled_targets(self._targets)
        self._compiled = compiled if compiled is not None else np.zeros((1, 38))
        self._python_targets = self._targets is not None and compiled is None
        chain = self._kinematics.chain
        self._fast = gains.task == "position" and chain is not None
        self._chain = pack_chain(chain) if chain is not None else None
        # the pose and top-down tasks on the chain: packed too, unless an orientation is sampled
        self._fast_pose = gains.task != "position" and chain is not None and not self._python_targets \
            and (targets is None or self._rotations is not None)
        self.layout = telemetry_layout(nv, gains.task)
        self._size = size = max(part.stop for part in self.layout.values())
        self._tau = self.layout["tau"]
        self._sigma_dot = slice(size + 5, size + 5 + n)

        self._rotation_input = targets is None and gains.task != "position"
        self.loop_sizes = loop_sizes(nq, nv, n, targets is None, self._rotation_input)
        self._loop_in = self.DeclareVectorInputPort("loop", sum(self.loop_sizes))
        ends = np.cumsum(self.loop_sizes).tolist()
        self._parts = [slice(a, b) for a, b in zip([0] + ends[:-1], ends)]  # views: np.split costs ~8 µs
        self._capture_index = self.DeclareDiscreteState(np.r_[-1.0, np.zeros(2 * n)])
        DeclareSegmentStartEvents(self, schedule, self._capture)
        self.DeclareStateOutputPort("captured", self._capture_index)
        deps = {self.time_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        self._out = np.empty(nv + n)
        self._row = np.empty(size + 5 + n)  # the fast path's row, reused by every evaluation
        self._static, self._kernel, self._rows_kernel = None, None, None
        if self._fast:
            self._static = pack_position(
                nq, schedule.table, self._gains, *self._chain, self._compiled, self._law.reset_sigma,
                targets is None or self._python_targets)
            self._kernel, self._rows_kernel = position_output, position_rows
        elif self._fast_pose:
            self._static = pack_pose(
                nq, TASKS.index(gains.task), self._rot_scale, schedule.table, self._gains, *self._chain,
                self._compiled, _NO_ROTATIONS if self._rotations is None else self._rotations,
                self._law.reset_sigma, targets is None, self._rotation_input)
            self._kernel, self._rows_kernel = pose_output, pose_rows
        # the compiled path end to end: the output's kernel, and ``rows`` in one call
        self._batch = self._kernel is not None and self._null_space is None and not self._python_targets
        self._general = (n != 3 and gains.pinv_damping > 0.0) or nv > 8  # general kernels only (``_call``)
        self.DeclareVectorOutputPort("tau_sigma_dot", nv + n, self._calc_packed_output if self._batch
                                     else self._calc_output, prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort("telemetry", size,
                                     lambda c, o: o.SetFromVector(self._eval(c)[:size]),
                                     prerequisites_of_calc=deps)
        self._load_kernels()

    def _load_kernels(self, path: str = "lean") -> None:
        """Evaluate the law once, now, on zero inputs (the outputs' own path: ``row`` passes
        the kernels the argument types a simulation does, the ``loop`` input's array marked
        read-only when the bindings hand it out so, as Drake 1.51's do): numba loads the machine
        code from its cache (50-150 ms) while the diagram is built, not at a run's first
        derivative evaluation, and one compiled version serves the simulation and ``row``
        (tests/unit/test_kernel_load.py); ``rows``' batch kernel is loaded here too.  The TBG
        and target kept for t = 0 are those of t = 0.  ``path``: the kernels' ``"lean"`` versions
        (what a run calls), or their ``"general"`` ones (``_call``)."""
        context = self.CreateDefaultContext()
        loop = np.zeros(self._loop_in.size())
        if self._rotation_input:
            loop[self._parts[4]] = IDENTITY_ROTATION
        self._loop_in.FixValue(context, loop)
        self._loop_writeable = bool(self._loop_in.EvalBasicVector(context).value().flags.writeable)
        self.row(*self.row_arguments(context), path=path)  # zero inputs: often a singular J
        if self._batch:  # the telemetry's kernel (``rows``)
            self.rows(np.zeros(1), *(None if p is None else p[None] for p in self.row_arguments(context)[1:]),
                      path=path)

    def load_general_kernels(self) -> None:
        """Load (or compile) the general versions of the law's kernels, those a run falls back to
        where the lean ones cannot solve (``controller.pinv_solve_into``; ``warm_up`` compiles
        them at install)."""
        if self._kernel is not None:
            self._load_kernels("general")

    @property
    def num_tasks(self) -> int:
        return self._n

    @property
    def telemetry_size(self) -> int:
        return self._size

    def _loop_parts(self, context) -> tuple:
        """([q; v], σ, captured, target or None, target_rotation or None): the ``loop`` input at
        ``context`` taken apart."""
        u, parts = self._loop_in.Eval(context), self._parts
        return (u[parts[0]], u[parts[1]], u[parts[2]], u[parts[3]] if len(parts) > 3 else None,
                u[parts[4]] if len(parts) > 4 else None)

    def loop_values(self, context) -> tuple:
        """([q; v], σ, captured, target or None): the ``loop`` input at ``context`` taken apart
        (``row_arguments`` adds the target's rotation)."""
        return self._loop_parts(context)[:4]

    def row_arguments(self, context) -> tuple:
        """``row``'s arguments at ``context``: (t, [q; v], σ, captured, target or None,
        target_rotation or None)."""
        return (context.get_time(), *self._loop_parts(context))

    def _eval(self, context) -> np.ndarray:
        """The row (telemetry, active segment, σ̇) at ``context``."""
        return self.row(*self.row_arguments(context))

    def _calc_output(self, context, output) -> None:
        row = self._eval(context)
        out = self._out
        out[:self._nv], out[self._nv:] = row[self._tau], row[self._sigma_dot]
        output.SetFromVector(out)

    def _calc_packed_output(self, context, output) -> None:
        """[τ; σ̇] of the compiled path (``position_output``, or ``pose_output`` for a task with
        orientation; no null-space term): the ``loop`` input as it is into the kernel that
        ``row`` calls too, which writes [τ; σ̇] into the output's own memory (and the row into a
        reused buffer)."""
        t, out = context.get_time(), output.get_mutable_value()
        u = self._loop_in.EvalBasicVector(context).value()
        if self._general:
            self._kernel(t, u, self._static, self._row, out, True)
        elif not self._kernel(t, u, self._static, self._row, out):  # (``_call``)
            with compile_notice():
                self._kernel(t, u, self._static, self._row, out, True)

    def _capture(self, context, state) -> None:
        """Store [index, s(t0), σ0] at a segment start (σ0: σ then, with ``sigma_policy`` reset)."""
        row = self._eval(context)
        index = row[self._size]
        if index < 0:
            return
        sigma = self.loop_values(context)[1] if self._law.reset_sigma else np.zeros(self._n)
        state.get_mutable_discrete_state(self._capture_index).SetFromVector(
            np.concatenate([[index], row[self.layout["s"]], sigma]))

    def row(self, t: float, qv: np.ndarray, sigma: np.ndarray, captured: np.ndarray,
            target: Optional[np.ndarray], rotation: Optional[np.ndarray] = None, *,
            path: str = "auto") -> np.ndarray:
        """The row (telemetry, active segment [index, t0, tf, β, phase], σ̇) from the time, the
        plant state [q; v], the integrator's σ, [index, s(t0), σ0] and the ``target`` (and
        ``target_rotation``) inputs' values (None: the system's own targets).  The compiled
        position path is the simulation's own kernel (``position_output``) on the same values.
        ``path``: which versions of the compiled kernels (``_call``)."""
        n = self._n
        if target is None:
            target = np.array(active_target_values(self._schedule, self._targets, t)[TARGET_PORT]) \
                if self._python_targets else _NO_TARGET
        if self._kernel is not None:
            row = np.empty(self._size + 5 + n)
            parts = [qv, sigma, captured, target] + ([] if rotation is None else [rotation])
            u = np.concatenate(parts)
            u.flags.writeable = self._loop_writeable  # the simulation's argument types (one kernel)
            self._call(self._kernel, float(t), u, self._static, row, np.empty(self._nv + n), path=path)
        else:
            if self._law.reset_sigma:
                sigma = sigma - captured[1 + n:]
            row = self._pose_row(t, qv, sigma, captured, target, rotation)
        if self._null_space is not None:  # redundant arms, optional (off by default)
            D, rate, q_start, limits = self._null_space
            J = self._kinematics.compute(qv[:self._nq], qv[self._nq:])[2]
            row[self._tau] += null_space_torque(J, qv[:self._nq], qv[self._nq:], q_start, D, rate, limits)
        return row

    def rows(self, t: np.ndarray, qv: np.ndarray, sigma: np.ndarray, captured: np.ndarray,
             target: Optional[np.ndarray] = None, rotation: Optional[np.ndarray] = None, *,
             path: str = "auto") -> np.ndarray:
        """``row`` at each of k logged samples (arrays with k rows; ``target`` / ``rotation``
        None without those inputs): the compiled path in one call (``position_rows`` or
        ``pose_rows``, the same kernel on the same values), else ``row`` per sample."""
        k = len(t)
        if self._batch:
            parts = [qv, sigma, captured] + [p for p in (target, rotation) if p is not None]
            U = np.ascontiguousarray(np.hstack(parts), dtype=float)
            U.flags.writeable = self._loop_writeable  # its rows the simulation's types (``row``)
            out = np.empty((k, self._size + 5 + self._n))
            self._call(self._rows_kernel, np.ascontiguousarray(t, dtype=float), U, self._static, out,
                       np.empty(self._nv + self._n), path=path)
            return out
        targets = [None] * k if target is None else target
        rotations = [None] * k if rotation is None else rotation
        return np.array([self.row(*values) for values in zip(
            np.asarray(t, dtype=float).tolist(), qv, sigma, captured, targets, rotations)])

    def _call(self, kernel, *args, path: str = "auto") -> None:
        """``kernel(*args)``, a compiled path (``interceptor_row``): ``path`` ``"auto"`` its lean
        version, then, where that cannot solve (it returns False), its general one (the very bits
        the general one alone gives: ``controller.pinv_solve_into``; compiled at its first use,
        with ``jit_notice``); ``"lean"`` the lean one alone (the row's τ and σ̇ may stay unwritten),
        ``"general"`` the general one alone (always, for a law that needs it at every call)."""
        if self._general or path == "general":
            kernel(*args, True)
        elif not kernel(*args) and path == "auto":
            with compile_notice():
                kernel(*args, True)

    @cached_property
    def _rotations(self):
        """The targets' compiled orientations (``orientation.compiled_rotations``), or None: a
        target port, or a sampled orientation (then evaluated in Python, ``_pose_row``)."""
        return None if self._targets is None else compiled_rotations(self._targets)

    def _pose_row(self, t, qv, sigma, captured, target, rotation) -> np.ndarray:
        """The row of any other task or plant (the pose and top-down tasks, a plant the chain
        cannot describe), compiled: ``pose_row`` on the chain, else the plant's kinematics and
        ``task_row``.  Only a sampled orientation of the system's own targets is evaluated here."""
        nq, n, rotations = self._nq, self._n, self._rotations
        if rotation is None:
            rotation = _NO_TARGET if rotations is not None or self._task == "position" else \
                np.array(active_rotation_values(self._schedule, self._targets, t))
        rotations = _NO_ROTATIONS if rotations is None else rotations
        row = np.empty(self._size + 5 + n)
        task, scale = TASKS.index(self._task), self._rot_scale
        if self._chain is not None:
            pose_row(float(t), qv, sigma, captured, target, rotation, task, scale, self._schedule.table,
                     self._gains, *self._chain, self._compiled, rotations, row)
        else:
            x, _, R, _, J_v, J_w = self._kinematics.compute_pose(qv[:nq], qv[nq:])
            f64 = np.ascontiguousarray
            task_row(float(t), x, f64(R), f64(J_v), f64(J_w), f64(qv[nq:]), sigma, captured, target,
                     rotation, task, scale, self._schedule.table, self._gains, self._compiled, rotations, row)
        return row


class PrescribedTimeInterceptor(Diagram):
    """Input ``state`` ([q; v] of the plant); outputs ``u`` (actuation), ``tau`` (joint torques),
    ``sigma`` (σ, the Integrator's state, n), ``captured`` ([index, s(t0), σ0]) and ``telemetry``;
    n the dimension of ``gains.task`` (``systems.task.error``: 3 for ``position``, 6 with orientation).

    With ``targets`` (one per segment, ``evaluate(t)`` → [x, ẋ, ẍ, …]) the target is
    computed inside (compiled for sinusoid, linear and ballistic targets); with ``targets=None``
    the system has an input port ``target`` ([x_r, ẋ_r, ẍ_r] of the active segment,
    e.g. a Kalman filter's estimate) and holds no target object at all; with an orientation
    task it then has an input ``target_rotation`` too ([R_r, ω_r, ω̇_r], 15).
    """

    def __init__(self, *, plant, frame, schedule: Schedule, gains: ControllerGains,
                 targets: Optional[Sequence] = None, posture: Optional[np.ndarray] = None):
        super().__init__()
        if targets is not None and len(targets) != len(schedule):
            raise ValueError(f"targets: one target per segment is needed, got {len(targets)} "
                             f"for {len(schedule)} segments")
        builder = DiagramBuilder()
        law = builder.AddNamedSystem("law", InterceptorLaw(
            plant=plant, frame=frame, schedule=schedule, gains=gains, targets=targets, posture=posture))
        nv, n = plant.num_velocities(), law.num_tasks
        split = builder.AddNamedSystem("split", Demultiplexer([nv, n]))
        sigma = builder.AddNamedSystem("sigma", Integrator(n))
        loop = builder.AddNamedSystem("loop", Multiplexer(law.loop_sizes))
        builder.Connect(law.GetOutputPort("tau_sigma_dot"), split.get_input_port())
        builder.Connect(split.get_output_port(1), sigma.get_input_port())
        builder.ExportInput(loop.get_input_port(0), "state")
        builder.Connect(sigma.get_output_port(), loop.get_input_port(1))
        builder.Connect(law.GetOutputPort("captured"), loop.get_input_port(2))
        builder.Connect(loop.get_output_port(), law.GetInputPort("loop"))
        if targets is None:
            builder.ExportInput(loop.get_input_port(3), "target")
        if len(law.loop_sizes) > 4:
            builder.ExportInput(loop.get_input_port(4), "target_rotation")
        BT = plant.MakeActuationMatrix().T
        tau = split.get_output_port(0)
        u = tau if BT.shape[0] == nv and np.array_equal(BT, np.eye(nv)) else None
        if u is None:
            gain = builder.AddNamedSystem("actuation", MatrixGain(BT))
            builder.Connect(tau, gain.get_input_port())
            u = gain.get_output_port()
        builder.ExportOutput(u, "u")
        builder.ExportOutput(tau, "tau")
        builder.ExportOutput(sigma.get_output_port(), "sigma")
        builder.ExportOutput(law.GetOutputPort("captured"), "captured")
        builder.ExportOutput(law.GetOutputPort("telemetry"), "telemetry")
        builder.BuildInto(self)
        self.law = law
        self.layout = law.layout
        self._targets = law._targets

    @property
    def has_target_input(self) -> bool:
        return self.HasInputPort("target")

    @property
    def has_rotation_input(self) -> bool:
        return self.HasInputPort("target_rotation")

    def telemetry_at(self, t: np.ndarray, plant_state: np.ndarray, sigma: np.ndarray,
                     captured: np.ndarray, target: Optional[np.ndarray] = None,
                     rotation: Optional[np.ndarray] = None) -> np.ndarray:
        """Telemetry rows for logged samples (time, plant state, σ, [index, s(t0), σ0], and the
        ``target`` / ``target_rotation`` inputs' values when the system has those ports): the
        law's ``rows`` on the logged values (no context, no cache entry)."""
        size = self.law.telemetry_size
        if len(t) == 0:
            return np.empty((0, size))
        f64 = lambda a: None if a is None else np.ascontiguousarray(a, dtype=float)  # noqa: E731
        rows = self.law.rows(t, f64(plant_state), f64(sigma), f64(captured),
                             f64(target) if self.has_target_input else None,
                             f64(rotation) if self.has_rotation_input else None)
        return rows[:, :size]
