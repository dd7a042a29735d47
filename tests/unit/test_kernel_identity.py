"""The fused position kernel (``position_output``: scratch and memo in its packed array, borrowed
views, everything inlined) gives the very bits of the blocks' kernels called one by one: the
chain, the TBG, the target, the surface and the torque.  A wrong offset in the packed array or
its scratch, or a memo that leaks one evaluation into the next, shows here."""

import numpy as np
import pytest
from pydrake.systems.framework import BasicVector

from ptint_drake.controllers.ptsmc.interceptor_row import (GAINS_HEAD, borrow, pack_chain, pack_position,
                                                           position_output)
from ptint_drake.controllers.ptsmc.law import smc_torque
from ptint_drake.controllers.ptsmc.sliding_surface import SurfaceLaw
from ptint_drake.robot import rvm1
from ptint_drake.robot.plant import parse_model
from ptint_drake.systems.task.chain import KinematicChain
from ptint_drake.systems.task.targets import SinusoidTarget
from ptint_drake.systems.task.tbg import gamma_gain, tbg_row

EPS, DELTA, K_GAIN = 1e-6, 1e-6, 50.0


def _blocks_row(chain, table, target, law, t, q, v, sigma, captured):
    """The row as the blocks compute it, kernel by kernel."""
    x, _, J_v, _ = chain.evaluate(q)
    xdot = np.zeros(3)
    for i in range(3):
        for k in range(len(v)):
            xdot[i] += J_v[i, k] * v[k]
    tbg = np.empty(10)
    tbg_row(float(t), table, EPS, DELTA, 0.0, tbg)
    ref = target.evaluate(t)
    surface = law.values(t, x - ref[:3], xdot - ref[3:6], tbg[4], tbg[5:10], captured[:4], sigma)
    tau = smc_torque(np.full(3, K_GAIN), J_v, surface[:3])
    return np.concatenate([x, xdot, ref[:9], tbg[:5], surface[:15], sigma, tau, tbg[5:10], surface[15:]])


@pytest.mark.parametrize("reset", [False, True])
def test_position_output_gives_the_blocks_bits(reset):
    plant = parse_model("rvm1")
    plant.Finalize()
    chain = KinematicChain.of(plant, plant.GetFrameByName(rvm1.END_EFFECTOR))
    table = np.array([[0.0, 1.2], [1.0, 1.5], [0.75, 0.6], [gamma_gain(1.0, 0.75), gamma_gain(1.5, 0.6)]])
    target = SinusoidTarget([0.24, 0.0, 0.3], [0.1, 0.1, 0.1], 1.5, [0.0, np.pi / 2, 0.0])
    law = SurfaceLaw(Lambda=5.0, k=3.0, switching="tanh", phi=0.01, k_hold=50.0)
    gains = np.r_[EPS, DELTA, 0.0, law.k, law.k_hold, law.code, law.phi, 0.0, law.Lambda, np.full(3, K_GAIN)]
    assert len(gains) == GAINS_HEAD + 6
    static = pack_position(3, table, gains, *pack_chain(chain), np.array([target.compiled, target.compiled]),
                           reset, False)
    rng = np.random.default_rng(7)
    row, out = np.empty(49), np.empty(6)
    for t in (0.0, 0.4, 0.4, 1.1, 1.3, 2.9):  # start, converging, memo hit, hold, next segment
        q, v, sigma = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3), rng.uniform(-0.1, 0.1, 3)
        captured = np.r_[0.0 if t < 1.2 else 1.0, rng.uniform(-0.1, 0.1, 3), rng.uniform(-0.1, 0.1, 3)]
        u = BasicVector(np.r_[q, v, sigma, captured]).value()  # the simulation's array (flags)
        position_output(t, u, static, row, out)
        expected = _blocks_row(chain, table, target, law, t, q, v,
                               sigma - captured[4:] if reset else sigma, captured)
        np.testing.assert_array_equal(row, expected)
        np.testing.assert_array_equal(out, np.r_[expected[38:41], expected[46:49]])


def test_a_singular_jacobian_falls_back_to_the_general_kernel():
    """At a singular J (rvm1's elbow at ±90°) the lean kernel a run calls returns False (its
    solve needs numpy's least squares, ``controller.pinv_solve_into``); the general one, called
    next, gives the blocks' bits (their ``smc_torque`` solves in general); the law falls back
    the same way (tests/unit/test_kernel_load.py)."""
    plant = parse_model("rvm1")
    plant.Finalize()
    chain = KinematicChain.of(plant, plant.GetFrameByName(rvm1.END_EFFECTOR))
    table = np.array([[0.0], [1.0], [0.75], [gamma_gain(1.0, 0.75)]])
    target = SinusoidTarget([0.24, 0.0, 0.3], [0.1, 0.1, 0.1], 1.5, [0.0, np.pi / 2, 0.0])
    law = SurfaceLaw(Lambda=5.0, k=3.0, switching="tanh", phi=0.01, k_hold=50.0)
    gains = np.r_[EPS, DELTA, 0.0, law.k, law.k_hold, law.code, law.phi, 0.0, law.Lambda, np.full(3, K_GAIN)]
    static = pack_position(3, table, gains, *pack_chain(chain), np.array([target.compiled]), False, False)
    q, v, sigma = np.array([0.3, 0.2, np.pi / 2]), np.array([0.1, -0.2, 0.3]), np.array([0.01, 0.0, -0.01])
    captured = np.r_[0.0, 0.02, -0.01, 0.03, 0.0, 0.0, 0.0]
    u = BasicVector(np.r_[q, v, sigma, captured]).value()
    row, out = np.full(49, 7.0), np.full(6, 7.0)
    assert not position_output(0.4, u, static, row, out)
    assert np.all(out == 7.0)  # τ and σ̇ not written
    assert position_output(0.4, u, static, row, out, True)
    expected = _blocks_row(chain, table, target, law, 0.4, q, v, sigma, captured)
    np.testing.assert_array_equal(row, expected)
    np.testing.assert_array_equal(out, np.r_[expected[38:41], expected[46:49]])


def test_a_borrowed_view_stays_inside_its_array():
    with pytest.raises(IndexError):
        borrow(np.zeros(5), 3, (3,))


@pytest.mark.parametrize("task, inputs", [("pose", False), ("top_down", False), ("pose", True)])
def test_pose_output_gives_the_allocating_kernels_bits(task, inputs):
    """The packed pose kernel (``pose_output``, the pose and top-down tasks' simulation path:
    scratch and memo in its packed array) gives the bits of ``pose_row`` (the chain and
    ``task_row`` in new arrays) at a sequence of times with repeats (the memo), with the
    system's own compiled target and orientation or with both as inputs (a filter's), with
    σ reset; ``rows`` (all samples in one call) gives the same bits again."""
    from ptint_drake.controllers.ptsmc.gains import ControllerGains
    from ptint_drake.controllers.ptsmc.interceptor import InterceptorLaw
    from ptint_drake.controllers.ptsmc.interceptor_row import pose_row
    from ptint_drake.systems.task.error import TASKS
    from ptint_drake.systems.task.orientation import OrientedTarget, SpinningOrientation
    from ptint_drake.systems.task.schedule import Schedule, Segment

    plant = parse_model("rvm1_6dof" if task == "pose" else "rvm1_5dof")
    plant.Finalize()
    target = OrientedTarget(SinusoidTarget([0.24, 0, 0.3], [0.1, 0.1, 0.1], 1.5, [0, 1.57, 0]),
                            SpinningOrientation([150.0, 50.0, 180.0], [0.0, -20.0, 30.0]))
    schedule = Schedule([Segment(0.0, 1.2, 0.75), Segment(1.5, 1.0, 0.5)])
    gains = ControllerGains(task=task, sigma_policy="reset")
    law = InterceptorLaw(plant=plant, frame=plant.GetFrameByName(rvm1.END_EFFECTOR), schedule=schedule,
                         gains=gains, targets=None if inputs else [target, target])
    assert law._batch and law._kernel.__name__ == "pose_output"
    nv = plant.num_velocities()
    rng = np.random.default_rng(11 + nv)
    times = [0.0, 0.3, 0.3, 0.9, 1.4, 1.7, 1.7, 2.9]
    rows, args = [], []
    for t in times:
        qv, sigma = rng.normal(scale=0.5, size=2 * nv), rng.normal(scale=0.01, size=6)
        captured = np.r_[float(schedule.active(t)), rng.normal(scale=0.1, size=12)]
        ref, rot = (np.array(target.evaluate(t))[:9], np.array(target.rotation_values(t))) if inputs \
            else (None, None)
        rows.append(law.row(t, qv, sigma, captured, ref, rot))
        args.append((t, qv, sigma, captured, ref, rot))
        expected = np.empty_like(rows[-1])
        targets = law._compiled if not inputs else np.zeros((1, 38))
        rotations = law._rotations if not inputs else np.zeros((1, 12))
        pose_row(float(t), qv, sigma - captured[7:], captured, np.empty(0) if ref is None else ref,
                 np.empty(0) if rot is None else rot, TASKS.index(task), 0.1, schedule.table, law._gains,
                 *law._chain, targets, rotations, expected)
        np.testing.assert_array_equal(rows[-1], expected)
    stacked = [np.array(column) for column in zip(*args)]
    batch = law.rows(stacked[0], *stacked[1:4], *(stacked[4:] if inputs else (None, None)))
    np.testing.assert_array_equal(batch, np.array(rows))
