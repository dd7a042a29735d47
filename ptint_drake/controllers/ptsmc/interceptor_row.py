"""One evaluation of the fused interceptor as compiled code (numba): the whole row at once.

``position_row`` chains the equation kernels for the position task end to end: the compiled
kinematic chain (``chain.chain_kinematics_into``, eq. 5), the target (``targets.target_row``, or a
given one), e = x − x_r (eq. 11), the TBG and α (``tbg.tbg_row``, paper eqs. 6-10, 13), the
surface (``sliding_surface.surface_law``, eqs. 16-17) and the torque (eq. 18:
``controller.pinv3_solve_into`` and ``gain_torque``, ``sliding_mode_torque_into``'s two steps
for 3 rows); ``task_row_into`` the same for any task from
the frame's kinematics (with orientation, the target's rotation from ``orientation.rotation_row``
or a given one, and the error ``task.task_error_of``), ``pose_output`` with the chain.  The
blocks call the same kernels one by one, so there is one implementation of each equation.

The parameters travel as a few arrays (each argument costs the call ~0.1-0.2 µs): ``gains`` =
[ϵ, δ, α_hold, k, k_hold, law, φ, λ (pinv damping), Λ (n), K (nv)] (``pack_gains``),
``segments`` = ``Schedule.table``, ``joints`` = [kinds; q index; v index] and ``geometry`` = the
chain's fixed transforms with each joint's axis (``pack_chain``). ``position_output`` takes all
of them as one array (``pack_position``) and the loop's values as one input vector [q; v; σ;
index, s(t0), σ0; x_r, ẋ_r, ẍ_r], so an evaluation passes five arguments (``pose_output``
likewise, ``pack_pose``, with [R_r, ω_r, ω̇_r] last); the same array holds the memo of the last
call and a scratch block for every intermediate (``chain.chain_kinematics_into``,
``controller.sliding_mode_torque_into``), so the simulation's evaluation allocates no memory;
its views are borrowed (``views.borrow``: no atomic reference counts).

numba inlines (``inline="always"``) by typing the callee's code again at every site, so the
row inlines only what it alone calls in a run (``position_row`` into ``position_output``, the
TBG, target, surface and 3-row solve), and calls the kernels shared with another entry point
(the chain, also ``chain.chain_kinematics``; ``task_row_into``, the TBG's ξ), which are then
compiled once; and the kernels a run calls leave numpy's solvers out (``general`` None: they
return False where the torque's solve would need them, and the caller calls them again with
``general=True``, ``InterceptorLaw._call``).  A cold compilation of ``position_output`` took
≈ 40 s of CPU, ≈ 10 s now, for the same speed (docs/speed.md).  Every kernel keeps its order of
operations, so the bits are those of the blocks (tests/unit/test_kernel_identity.py).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ptint_drake.controllers.ptsmc.law import (gain_torque, pinv3_solve_into, pinv_work_size,
                                               sliding_mode_torque_into)
from ptint_drake.controllers.ptsmc.sliding_surface import SWITCHING_LAWS, surface_law
from ptint_drake.systems.task.chain import chain_kinematics, chain_kinematics_into
from ptint_drake.systems.task.error import POSITION, task_error_of, task_jacobian_of
from ptint_drake.systems.task.orientation import ROTATION_WIDTH, rotation_row
from ptint_drake.systems.task.targets import target_row
from ptint_drake.systems.task.tbg import tbg_row
from ptint_drake.systems.task.views import borrow, copy_into

GAINS_HEAD = 8  # ϵ, δ, α_hold, k, k_hold, law, φ, λ; then Λ (n) and K (nv)


def pack_gains(gains, n: int, K: np.ndarray) -> np.ndarray:
    """``gains`` (a ``ControllerGains``) as the ``gains`` array of the kernels."""
    head = [gains.epsilon, gains.delta, gains.alpha_hold, gains.k, gains.k_hold,
            SWITCHING_LAWS.index(gains.switching), gains.phi, gains.pinv_damping]
    Lambda = np.broadcast_to(np.asarray(gains.Lambda, dtype=float), (n,))
    return np.concatenate([np.asarray(head, dtype=float), Lambda, K])


def pack_chain(chain) -> tuple:
    """(joints, geometry) of a ``KinematicChain``: [kinds; q index; v index] (3 × n, floats) and the
    fixed transforms X_0 … X_n as [R; pᵀ] with row 4 = the next joint's axis ((n + 1) × 5 × 3)."""
    return chain.joints, chain.geometry


@njit(cache=True, inline="always")
def position_row(t, qv, sigma, captured, target, segments, gains, joints, geometry, targets, memo, work,
                 out, general=None) -> bool:
    """``out`` ← the fused interceptor's row for the position task (``interceptor.telemetry_layout``
    then [index, t0, tf, β, phase] then σ̇): x, ẋ, x_r, ẋ_r, ẍ_r, ξ…ξ⃛, α, s_x, e, ė, s, s_d,
    σ, τ.  ``target``: [x_r, ẋ_r, ẍ_r] (9), or empty to evaluate ``targets`` (one compiled row
    per segment, ``targets.compiled_targets``) at t.  ``memo`` = [t, TBG row (10), target (12)]
    of the last call: the TBG and the compiled target are functions of t alone, and one
    evaluation in three (an RK3 step's first stage) comes at the previous one's time.  ``work``:
    scratch (``work_size``) for every intermediate, so that a call allocates nothing.  False (the
    torque and σ̇ not written) where the torque's solve needs ``general``
    (``controller.pinv_solve_into``)."""
    nv, n_joints = len(gains) - GAINS_HEAD - 3, joints.shape[1]
    nq = len(qv) - nv
    x, R, xdot, e, edot = work[0:3], borrow(work, 3, (3, 3)), work[12:15], work[15:18], work[18:21]
    surface, solve = work[21:39], work[39:51]  # 6n; n² + n
    J_v, J_w = borrow(work, 51, (3, nv)), borrow(work, 51 + 3 * nv, (3, nv))
    chain_kinematics_into(qv[:nq], joints[0], joints[1], joints[2], geometry[:, :4], geometry[:-1, 4],
                          x, R, J_v, J_w, borrow(work, 51 + 6 * nv, (2 * n_joints + 5, 3)))
    v = qv[nq:]
    for i in range(3):
        xdot[i] = 0.0
        for k in range(nv):
            xdot[i] += J_v[i, k] * v[k]
    tbg, ref = memo[1:11], memo[11:23]
    if memo[0] != t:  # (NaN at first)
        tbg_row(t, segments, gains[0], gains[1], gains[2], tbg)
        if len(target) == 0:
            i = max(np.searchsorted(segments[0], t, side="right") - 1, 0)
            target_row(targets[i], t, ref)
        memo[0] = t
    if len(target) != 0:
        copy_into(ref, 0, target[:9])
    for i in range(3):
        e[i], edot[i] = x[i] - ref[i], xdot[i] - ref[3 + i]
    surface_law(t, e, edot, tbg[4], tbg[5:10], captured, sigma, gains[GAINS_HEAD:GAINS_HEAD + 3],
                gains[3], gains[4], int(gains[5]), gains[6], surface)
    tau = out[38:38 + nv]  # τ = −K J⁺ s_x (``controller.sliding_mode_torque_into``, 3 rows)
    if not pinv3_solve_into(J_v, surface[:3], gains[7], tau, solve, general):
        return False
    gain_torque(gains[GAINS_HEAD + 3:], tau)
    copy_into(out, 0, x)
    copy_into(out, 3, xdot)
    copy_into(out, 6, ref[:9])
    copy_into(out, 15, tbg[:5])
    copy_into(out, 20, surface[:15])
    copy_into(out, 35, sigma)
    copy_into(out, 38 + nv, tbg[5:10])
    copy_into(out, 43 + nv, surface[15:18])
    return True


def work_size(nv: int, n_joints: int) -> int:
    """Floats of ``position_row``'s scratch: x, R, ẋ, e, ė, the surface row, the solve's, J_v,
    J_ω, the chain's (``chain.chain_kinematics_into``) and σ (``position_output``)."""
    return 51 + 6 * nv + 6 * n_joints + 15 + 3


TASK_MEMO = 38  # task_row_into's memo: [t, TBG row (10), target (12), rotation (15)]


@njit(cache=True)
def task_work_size(n: int, nv: int) -> int:
    """Floats of ``task_row_into``'s scratch for a task of dimension n on nv joints: ẋ, ω, R, [e; ė],
    J, the surface row and the solve's (``controller.pinv_work_size``)."""
    return 15 + 2 * n + n * nv + 6 * n + pinv_work_size(n, nv)


@njit(cache=True)
def task_row_into(t, x, R, J_v, J_w, v, sigma, captured, target, rotation, task, rot_scale, segments, gains,
                  targets, rotations, memo, work, out, general=None) -> bool:
    """``out`` ← the row of any task (``interceptor.telemetry_layout(nv, task)`` then
    [index, t0, tf, β, phase] then σ̇) from the frame's position x, orientation R (3 × 3),
    Jacobians J_v, J_ω (3 × nv) and the joint speeds v.  ``task``: its code (``task.TASKS``);
    ``target``: [x_r, ẋ_r, ẍ_r] (≥ 9) or empty to evaluate ``targets`` (``targets.target_row``);
    ``rotation``: [R_r, ω_r, ω̇_r] (15) or empty to evaluate ``rotations``
    (``orientation.rotation_row``), both at t for the active segment.  ``memo`` (``TASK_MEMO``):
    the TBG, target and rotation of the last call's t, functions of t alone (NaN at first);
    ``work``: scratch (``task_work_size``).  False (τ, σ̇ not written): the solve needs ``general``."""
    nv, n = len(v), 3 if task == POSITION else 6
    xdot, omega, R9, err = work[0:3], work[3:6], work[6:15], work[15:15 + 2 * n]
    o = 15 + 2 * n
    J = borrow(work, o, (n, nv))
    o += n * nv
    surface = work[o:o + 6 * n]
    solve = work[o + 6 * n:]
    for i in range(3):
        xdot[i], omega[i] = 0.0, 0.0
        for k in range(nv):
            xdot[i] += J_v[i, k] * v[k]
            omega[i] += J_w[i, k] * v[k]
        for j in range(3):
            R9[3 * i + j] = R[i, j]
    tbg, ref, rot = memo[1:11], memo[11:23], memo[23:38]
    if memo[0] != t:  # (NaN at first)
        tbg_row(t, segments, gains[0], gains[1], gains[2], tbg)
        active = max(np.searchsorted(segments[0], t, side="right") - 1, 0)
        if len(target) == 0:
            target_row(targets[active], t, ref)
        if task != POSITION and len(rotation) == 0:
            rotation_row(rotations[active], t, rot)
        memo[0] = t
    if len(target) != 0:
        copy_into(ref, 0, target[:9])
    if task != POSITION and len(rotation) != 0:
        copy_into(rot, 0, rotation[:15])
    task_error_of(task, rot_scale, x, xdot, ref[0:3], ref[3:6], R9, omega, rot, err)
    task_jacobian_of(J_v, J_w, rot_scale, J)
    surface_law(t, err[:n], err[n:], tbg[4], tbg[5:10], captured, sigma, gains[GAINS_HEAD:GAINS_HEAD + n],
                gains[3], gains[4], int(gains[5]), gains[6], surface)
    m = 20 + 5 * n
    if not sliding_mode_torque_into(gains[GAINS_HEAD + n:], J, surface[:n], gains[7], out[m + n:m + n + nv],
                                    solve, general):
        return False
    copy_into(out, 0, x)
    copy_into(out, 3, xdot)
    copy_into(out, 6, ref[:9])
    copy_into(out, 15, tbg[:5])
    copy_into(out, 20, surface[:5 * n])
    copy_into(out, m, sigma)
    m += n + nv
    if task != POSITION:
        copy_into(out, m, R9)
        copy_into(out, m + 9, omega)
        copy_into(out, m + 12, rot)
        m += 27
    copy_into(out, m, tbg[5:10])
    copy_into(out, m + 5, surface[5 * n:])
    return True


@njit(cache=True)
def task_row(t, x, R, J_v, J_w, v, sigma, captured, target, rotation, task, rot_scale, segments, gains,
             targets, rotations, out):
    """``task_row_into`` with its own memo and scratch (the row of a plant the compiled chain
    cannot describe, from Drake's kinematics)."""
    n = 3 if task == POSITION else 6
    task_row_into(t, x, R, J_v, J_w, v, sigma, captured, target, rotation, task, rot_scale, segments, gains,
                  targets, rotations, np.full(TASK_MEMO, np.nan), np.empty(task_work_size(n, len(v))), out,
                  True)


@njit(cache=True)
def pose_row(t, qv, sigma, captured, target, rotation, task, rot_scale, segments, gains, joints, geometry,
             targets, rotations, out):
    """``task_row`` with the kinematics of the compiled chain (``chain.chain_kinematics``, joints and
    geometry of ``pack_chain``) at the plant state ``qv`` = [q; v]: the whole row of the pose and
    top-down tasks (or the position task) in one call."""
    nv = len(gains) - GAINS_HEAD - (3 if task == POSITION else 6)
    nq = len(qv) - nv
    x, R, J_v, J_w = chain_kinematics(qv[:nq], joints, geometry, nv)
    task_row(t, x, R, J_v, J_w, qv[nq:], sigma, captured, target, rotation, task, rot_scale, segments,
             gains, targets, rotations, out)


POSITION_HEAD = 8  # nq, nv, segments, joints, targets, target width, σ reset, target given
MEMO = 23  # position_row's memo: [t, TBG row (10), target (12)]


def pack_position(nq: int, segments, gains, joints, geometry, targets, reset: bool,
                  given_target: bool) -> np.ndarray:
    """The static arrays of ``position_row`` as one float array for ``position_output``: a head
    [nq, nv, segment count, joint count, target count, target row width, σ reset (0/1), target in
    the input (0/1)], then ``segments``, ``gains``, ``joints`` (whole numbers as floats),
    ``geometry`` and ``targets`` (compiled rows), each flattened, then ``position_row``'s memo
    (``MEMO`` slots) and its scratch (``work_size``), both written by every call."""
    nv = len(gains) - GAINS_HEAD - 3
    head = [nq, nv, segments.shape[1], joints.shape[1], targets.shape[0], targets.shape[1],
            float(reset), float(given_target)]
    return _packed(head, (segments, gains, joints, geometry, targets), MEMO, work_size(nv, joints.shape[1]))


def _packed(head, arrays, memo: int, work: int) -> np.ndarray:
    """[head; each of ``arrays`` flattened; a memo of ``memo`` NaNs; ``work`` zeros] as floats."""
    return np.concatenate([np.asarray(head, dtype=float), *(np.ravel(a).astype(float) for a in arrays),
                           np.full(memo, np.nan), np.zeros(work)])


@njit(cache=True, inline="always")
def _static_parts(static, o, n, nv):
    """(segments, gains, joints, geometry, targets, the offset after them): the borrowed views of a
    packed array (``pack_position``, ``pack_pose``) whose head ends at ``o``, for a task of
    dimension n on nv joints (head slots 2-5: segment, joint and target counts, target width)."""
    n_seg, n_joints, n_targets, width = int(static[2]), int(static[3]), int(static[4]), int(static[5])
    segments = borrow(static, o, (4, n_seg))
    o += 4 * n_seg
    gains = borrow(static, o, (GAINS_HEAD + n + nv,))
    o += GAINS_HEAD + n + nv
    joints = borrow(static, o, (3, n_joints))
    o += 3 * n_joints
    geometry = borrow(static, o, (n_joints + 1, 5, 3))
    o += 15 * (n_joints + 1)
    targets = borrow(static, o, (n_targets, width))
    return segments, gains, joints, geometry, targets, o + n_targets * width


@njit(cache=True, inline="always")
def _loop_sigma(u, m, n, captured, reset, sigma) -> None:
    """``sigma`` (n) ← the Integrator's σ at u[m:m + n], minus σ0 (``captured``[1 + n:]) when
    ``reset`` (``sigma_policy`` reset)."""
    for i in range(n):
        sigma[i] = u[m + i] - captured[1 + n + i] if reset else u[m + i]


@njit(cache=True)
def position_output(t, u, static, row, tau_sigma_dot, general=None) -> bool:
    """``position_row`` on a packed input: ``u`` = [q; v; σ (the Integrator's); captured
    [index, s(t0), σ0]; the target [x_r, ẋ_r, ẍ_r] when the system has a target input],
    ``static`` from ``pack_position``; ``row`` ← the row, ``tau_sigma_dot`` ← [τ; σ̇]
    (σ − σ0 used with ``sigma_policy`` reset).  Allocates nothing, and its views are borrowed
    (``borrow``).  False where the torque's solve needs ``general``: call it again with
    ``general=True`` (``controller.pinv_solve_into``)."""
    nq, nv = int(static[0]), int(static[1])
    segments, gains, joints, geometry, targets, o = _static_parts(static, POSITION_HEAD, 3, nv)
    memo, work = borrow(static, o, (MEMO,)), borrow(static, o + MEMO, (len(static) - o - MEMO,))
    m = nq + nv
    sigma = work[len(work) - 3:]
    captured = borrow(u, m + 3, (7,))
    _loop_sigma(u, m, 3, captured, static[6] != 0.0, sigma)
    target = borrow(u, m + 10, (9 if static[7] != 0.0 else 0,))
    if not position_row(t, borrow(u, 0, (m,)), sigma, captured, target, segments, gains, joints, geometry,
                        targets, memo, work, borrow(row, 0, (len(row),)), general):
        return False
    copy_into(tau_sigma_dot, 0, row[38:38 + nv])
    copy_into(tau_sigma_dot, nv, row[43 + nv:46 + nv])
    return True


@njit(cache=True)
def position_rows(t, U, static, rows, tau_sigma_dot, general=None) -> bool:
    """``position_output`` at each logged sample k: ``rows[k]`` ← the row at time t[k] from the
    ``loop`` input's values U[k] then (the telemetry of a run in one call, not one per sample);
    ``tau_sigma_dot`` is scratch.  False where a sample needs ``general``."""
    for k in range(len(t)):
        if general is None:  # (as Python calls it: one compiled version)
            if not position_output(t[k], U[k], static, rows[k], tau_sigma_dot):
                return False
        elif not position_output(t[k], U[k], static, rows[k], tau_sigma_dot, general):
            return False
    return True


POSE_HEAD = 12  # POSITION_HEAD's, then the task code, c (rot_scale), rotation count, rotation given


def pose_work_size(n: int, nv: int, n_joints: int) -> int:
    """Floats of ``pose_output``'s scratch: x, R, J_v, J_ω, the chain's, σ and ``task_row_into``'s."""
    return 12 + 6 * nv + 3 * (2 * n_joints + 5) + n + task_work_size(n, nv)


def pack_pose(nq: int, task: int, rot_scale: float, segments, gains, joints, geometry, targets, rotations,
              reset: bool, given_target: bool, given_rotation: bool) -> np.ndarray:
    """``pack_position`` for any task (``task.TASKS`` code ``task``, c = ``rot_scale``): the head
    [nq, nv, segment count, joint count, target count, target row width, σ reset, target in the
    input, task, c, rotation count, rotation in the input], then ``segments``, ``gains``,
    ``joints``, ``geometry``, ``targets`` and ``rotations`` (compiled orientations,
    ``ROTATION_WIDTH`` each) flattened, then the memo (``TASK_MEMO``) and the scratch
    (``pose_work_size``)."""
    n = 3 if task == POSITION else 6
    nv = len(gains) - GAINS_HEAD - n
    rotations = np.asarray(rotations, dtype=float).reshape(-1, ROTATION_WIDTH)
    head = [nq, nv, segments.shape[1], joints.shape[1], targets.shape[0], targets.shape[1], float(reset),
            float(given_target), task, rot_scale, rotations.shape[0], float(given_rotation)]
    return _packed(head, (segments, gains, joints, geometry, targets, rotations), TASK_MEMO,
                   pose_work_size(n, nv, joints.shape[1]))


@njit(cache=True)
def pose_output(t, u, static, row, tau_sigma_dot, general=None) -> bool:
    """``position_output`` for any task on the compiled chain (the pose and top-down tasks):
    ``u`` = [q; v; σ (n); captured [index, s(t0), σ0] (1 + 2n); the target [x_r, ẋ_r, ẍ_r] (9)
    when the system has a target input; [R_r, ω_r, ω̇_r] (15) when it has a rotation input],
    ``static`` from ``pack_pose``; ``row`` ← the row (``task_row_into``), ``tau_sigma_dot`` ←
    [τ; σ̇].  Its views are borrowed and its scratch is in ``static``.  False where the torque's
    solve needs ``general`` (``position_output``)."""
    nq, nv, n_joints = int(static[0]), int(static[1]), int(static[3])
    task, n_rot = int(static[8]), int(static[10])
    n = 3 if task == POSITION else 6
    segments, gains, joints, geometry, targets, o = _static_parts(static, POSE_HEAD, n, nv)
    rotations = borrow(static, o, (n_rot, ROTATION_WIDTH))
    o += n_rot * ROTATION_WIDTH
    memo = borrow(static, o, (TASK_MEMO,))
    work = borrow(static, o + TASK_MEMO, (len(static) - o - TASK_MEMO,))
    x, R = work[0:3], borrow(work, 3, (3, 3))
    J_v, J_w = borrow(work, 12, (3, nv)), borrow(work, 12 + 3 * nv, (3, nv))
    c = 12 + 6 * nv
    chain = borrow(work, c, (2 * n_joints + 5, 3))
    c += 3 * (2 * n_joints + 5)
    sigma = work[c:c + n]
    m = nq + nv
    captured = borrow(u, m + n, (1 + 2 * n,))
    _loop_sigma(u, m, n, captured, static[6] != 0.0, sigma)
    p = m + 3 * n + 1
    given_target = 9 if static[7] != 0.0 else 0
    target = borrow(u, p, (given_target,))
    rotation = borrow(u, p + given_target, (15 if static[11] != 0.0 else 0,))
    chain_kinematics_into(borrow(u, 0, (nq,)), joints[0], joints[1], joints[2], geometry[:, :4],
                          geometry[:-1, 4], x, R, J_v, J_w, chain)
    if not task_row_into(t, x, R, J_v, J_w, borrow(u, nq, (nv,)), sigma, captured, target, rotation, task,
                         static[9], segments, gains, targets, rotations, memo, work[c + n:],
                         borrow(row, 0, (len(row),)), general):
        return False
    m = 20 + 6 * n
    copy_into(tau_sigma_dot, 0, row[m:m + nv])
    copy_into(tau_sigma_dot, nv, row[len(row) - n:])
    return True


@njit(cache=True)
def pose_rows(t, U, static, rows, tau_sigma_dot, general=None) -> bool:
    """``pose_output`` at each logged sample k (``position_rows`` for any task)."""
    for k in range(len(t)):
        if general is None:  # (as Python calls it: one compiled version)
            if not pose_output(t[k], U[k], static, rows[k], tau_sigma_dot):
                return False
        elif not pose_output(t[k], U[k], static, rows[k], tau_sigma_dot, general):
            return False
    return True
