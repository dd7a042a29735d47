"""Each LeafSystem with fixed inputs against its equation (SPEC section 2.3)."""

import numpy as np
import pytest

from ptint_drake.controllers.ptsmc.law import SlidingModeController
from ptint_drake.controllers.ptsmc.sliding_surface import SlidingSurface, SurfaceLaw, switching_law
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import LinearTarget, SinusoidTarget, TargetSource
from ptint_drake.systems.task.tbg import TimeBaseGenerator

SCHED = Schedule([Segment(0.0, 1.5, 0.75), Segment(2.0, 1.0, 0.5)])


def _surface_context(surface, t, x, xdot, x_r, xdot_r, alpha, segment, sigma, captured):
    ctx = surface.CreateDefaultContext()
    ctx.SetTime(t)
    for name, value in (("x", x), ("xdot", xdot), ("x_r", x_r), ("xdot_r", xdot_r),
                        ("alpha", [alpha]), ("segment", segment)):
        surface.GetInputPort(name).FixValue(ctx, np.asarray(value, dtype=float))
    ctx.SetContinuousState(sigma)
    ctx.SetDiscreteState(np.asarray(captured, dtype=float))
    return ctx


def test_surface_outputs_follow_equations():
    surface = SlidingSurface(SCHED, Lambda=5.0, k=3.0, switching="sign")
    x, xdot = np.array([0.2, 0.1, 0.3]), np.array([0.05, -0.02, 0.01])
    x_r, xdot_r = np.array([0.24, 0.0, 0.3]), np.array([0.15, 0.0, 0.15])
    alpha, sigma, s0 = 2.5, np.array([0.1, -0.2, 0.3]), np.array([-0.15, 0.0, -0.15])
    t = 0.7
    ctx = _surface_context(surface, t, x, xdot, x_r, xdot_r, alpha, [0, 0.0, 1.5, 0.75, 1],
                           sigma, [0, *s0])
    e, edot = x - x_r, xdot - xdot_r
    s = edot + alpha * e
    s_d = s0 * np.exp(-3.0 * t)
    np.testing.assert_allclose(surface.GetOutputPort("e").Eval(ctx), e)
    np.testing.assert_allclose(surface.GetOutputPort("edot").Eval(ctx), edot)
    np.testing.assert_allclose(surface.GetOutputPort("s").Eval(ctx), s)
    np.testing.assert_allclose(surface.GetOutputPort("s_d").Eval(ctx), s_d)
    np.testing.assert_allclose(surface.GetOutputPort("s_x").Eval(ctx), s - s_d + 5.0 * sigma)
    deriv = surface.EvalTimeDerivatives(ctx).CopyToVector()
    np.testing.assert_allclose(deriv, np.sign(s - s_d))


def test_surface_hold_decay_and_capture_instant():
    surface = SlidingSurface(SCHED, k=3.0, k_hold=50.0)
    s0 = np.array([0.1, 0.0, -0.1])
    args = ([0.2, 0.1, 0.3], [0, 0, 0], [0.2, 0.1, 0.3], [0, 0, 0], 0.0)
    ctx = _surface_context(surface, 1.7, *args, [0, 0.0, 1.5, 0.75, 2], np.zeros(3), [0, *s0])
    np.testing.assert_allclose(surface.GetOutputPort("s_d").Eval(ctx),
                               s0 * np.exp(-3.0 * 1.5 - 50.0 * 0.2))
    # at a new segment's start, before its event: s_d is s itself, so s_x = Λσ exactly
    ctx = _surface_context(surface, 2.0, [0.2, 0.1, 0.3], [0.1, 0, 0], [0.25, 0.0, 0.3],
                           [0, 0.1, 0], 0.0, [1, 2.0, 1.0, 0.5, 1], np.array([1.0, 2, 3]), [0, *s0])
    np.testing.assert_allclose(surface.GetOutputPort("s_x").Eval(ctx), 5.0 * np.array([1.0, 2, 3]))


@pytest.mark.parametrize("law", ["sign", "tanh", "sat"])
def test_switching_laws(law):
    switch = switching_law(law, 0.01)
    out = np.concatenate([switch([-1.0, -1e-3, 0.0]), switch([1e-3, 1.0, 2.0])[:2]])
    assert out[0] == -1.0 or out[0] == pytest.approx(-1.0)
    assert out[-1] == pytest.approx(1.0)
    assert out[2] == 0.0
    assert np.all(np.diff(out) >= 0)
    if law != "sign":  # a boundary layer is continuous: small w, small σ̇
        assert abs(out[3]) < 0.2


@pytest.mark.parametrize("nv, K, seed", [(3, 50.0, 0), (5, [1, 2, 3, 4, 5], 1)])
def test_controller_is_minus_K_Jpinv_s(nv, K, seed):
    """Square J: a solve; redundant J (5 joints): the minimum-norm solution."""
    ctrl = SlidingModeController(nv, K=K)
    ctx = ctrl.CreateDefaultContext()
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(3, nv))
    s_x = rng.normal(size=3)
    ctrl.GetInputPort("J").FixValue(ctx, J.ravel())
    ctrl.GetInputPort("s_x").FixValue(ctx, s_x)
    expected = -np.broadcast_to(np.asarray(K, dtype=float), (nv,)) * (np.linalg.pinv(J) @ s_x)
    np.testing.assert_allclose(ctrl.GetOutputPort("tau").Eval(ctx), expected, atol=1e-12)


def test_controller_uses_kinematics_only():
    """Model-free: the controller's only inputs are s_x and J; it holds no plant."""
    ctrl = SlidingModeController(3)
    assert sorted(ctrl.get_input_port(i).get_name() for i in range(ctrl.num_input_ports())) == ["J", "s_x"]
    assert not any("plant" in k.lower() for k in vars(ctrl))


def test_targets_derivatives():
    targets = [SinusoidTarget([0.24, 0, 0.3], [0.1] * 3, 1.5, [0, np.pi / 2, 0]),
               LinearTarget([0.3, -0.15, 0.15], [0, 0.1, 0])]
    h = 1e-5
    for tg in targets:
        for t in (0.0, 0.4, 1.3):
            f = [tg.evaluate(t + k * h) for k in (-1, 0, 1)]
            for d in range(3):
                np.testing.assert_allclose(f[1][3 * (d + 1):3 * (d + 2)],
                                           (f[2][3 * d:3 * (d + 1)] - f[0][3 * d:3 * (d + 1)]) / (2 * h),
                                           atol=1e-6)
    # the paper's curve (eq. 28)
    t = 0.9
    np.testing.assert_allclose(targets[0].evaluate(t)[0:6], [
        0.24 + 0.1 * np.sin(1.5 * t), 0.1 * np.cos(1.5 * t), 0.3 + 0.1 * np.sin(1.5 * t),
        0.15 * np.cos(1.5 * t), -0.15 * np.sin(1.5 * t), 0.15 * np.cos(1.5 * t)], atol=1e-15)


def test_target_source_switches_with_segments():
    targets = [LinearTarget([0.3, -0.15, 0.15], [0, 0.1, 0]), LinearTarget([0.2, -0.23, 0.25], [0, 0.1, 0])]
    src = TargetSource(SCHED, targets)
    ctx = src.CreateDefaultContext()
    ctx.SetTime(1.99)
    np.testing.assert_allclose(src.GetOutputPort("x_r").Eval(ctx), [0.3, -0.15 + 0.199, 0.15])
    ctx.SetTime(2.0)
    np.testing.assert_allclose(src.GetOutputPort("x_r").Eval(ctx), [0.2, -0.23 + 0.2, 0.25])
    np.testing.assert_allclose(src.GetOutputPort("objects").Eval(ctx),
                               [0.3, 0.05, 0.15, 0.2, -0.03, 0.25])
    with pytest.raises(ValueError, match="one target per segment"):
        TargetSource(SCHED, targets[:1])


def test_schedule_validation():
    with pytest.raises(ValueError, match=r"interceptions\[1\].start"):
        Schedule([Segment(0.0, 1.0, 0.5), Segment(0.5, 1.0, 0.5)])
    with pytest.raises(ValueError, match="beta"):
        Schedule([Segment(0.0, 1.0, 1.0)])
    assert SCHED.active(-0.1) == -1 and SCHED.active(0.0) == 0 and SCHED.active(2.0) == 1
    assert TimeBaseGenerator(SCHED).schedule is SCHED


def test_square_solve_matches_numpy_and_survives_singular():
    """The compiled 3 × 3 solve (Cramer's rule) against numpy; least squares when singular."""
    from ptint_drake.controllers.ptsmc.law import pinv_apply

    rng = np.random.default_rng(5)
    for _ in range(200):
        J = rng.normal(size=(3, 3))
        b = rng.normal(size=3)
        np.testing.assert_allclose(pinv_apply(J, b), np.linalg.solve(J, b), rtol=1e-9, atol=1e-9)
    singular = np.array([[1.0, 2, 3], [2, 4, 6], [0, 1, 1]])
    np.testing.assert_allclose(pinv_apply(singular, [1.0, 1.0, 1.0]),
                               np.linalg.lstsq(singular, np.ones(3), rcond=None)[0], atol=1e-12)


@pytest.mark.parametrize("nv, damping", [(5, 0.0), (6, 0.0), (7, 0.0), (6, 0.05)])
def test_six_row_pinv_is_numpys_least_squares(nv, damping):
    """6-row tasks: the minimum-norm least-squares solution (damped: Jᵀ(JJᵀ + λ²I)⁻¹ b)."""
    from ptint_drake.controllers.ptsmc.law import pinv_apply

    rng = np.random.default_rng(nv)
    J, b = rng.normal(size=(6, nv)), rng.normal(size=6)
    expected = (J.T @ np.linalg.solve(J @ J.T + damping**2 * np.eye(6), b) if damping
                else np.linalg.lstsq(J, b, rcond=None)[0])
    np.testing.assert_allclose(pinv_apply(J, b, damping), expected, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("nv", [5, 6, 8])
def test_six_row_pinv_of_a_rank_deficient_jacobian_is_the_svds(nv):
    """A 6-row J with two equal columns (a wrist singularity) or a zero row: the Householder
    solve says rank-deficient and the SVD's minimum-norm least-squares solution is returned
    (not a huge or NaN one); a nearly singular J (condition ~1e8) still matches numpy."""
    from ptint_drake.controllers.ptsmc.law import pinv_apply

    rng = np.random.default_rng(10 + nv)
    b = rng.normal(size=6)
    equal = rng.normal(size=(6, nv))
    equal[:, -1] = equal[:, -2]
    zero_row = rng.normal(size=(6, nv))
    zero_row[2] = 0.0
    for J in (equal, zero_row):
        x = pinv_apply(J, b)
        np.testing.assert_allclose(x, np.linalg.lstsq(J, b, rcond=None)[0], atol=1e-10)
        assert np.all(np.isfinite(x)) and np.linalg.norm(x) < 1e3
    U, _, Vt = np.linalg.svd(rng.normal(size=(6, nv)), full_matrices=False)
    J = U @ np.diag(np.logspace(0, -8, min(6, nv))) @ Vt
    np.testing.assert_allclose(pinv_apply(J, b), np.linalg.lstsq(J, b, rcond=None)[0], rtol=1e-6)


@pytest.mark.parametrize("law", ["sign", "tanh", "sat"])
def test_switching_law_is_numpys(law):
    """The compiled law equals numpy's array form (sign, clip exactly; tanh to the last bits)."""
    reference = {"sign": np.sign, "tanh": lambda w: np.tanh(w / 0.01),
                 "sat": lambda w: np.clip(w / 0.01, -1.0, 1.0)}[law]
    switch = switching_law(law, 0.01)
    w = np.random.default_rng(3).normal(scale=0.02, size=(500, 3))
    for row in w:
        np.testing.assert_allclose(switch(row.tolist()), reference(row), rtol=4e-16, atol=0)
    with pytest.raises(ValueError, match="controller.switching"):
        switching_law("relay", 0.01)


def test_surface_law_matches_the_paper_equations():
    """``SurfaceLaw.values`` (what the fused system and the block call) against eqs. 11, 16, 17
    written with numpy arrays: e, ė, s = ė + αe, s_d = s(t0) e^(−kτ) (hold: e^(−k tf − k_hold(τ − tf))),
    s_x = s − s_d + Λσ, σ̇ = tanh((s − s_d)/φ)."""
    from ptint_drake.systems.task.error import task_error

    law = SurfaceLaw(Lambda=5.0, k=3.0, switching="tanh", phi=0.01, k_hold=50.0)
    rng = np.random.default_rng(11)
    for t, phase_tf in ((0.7, 1.5), (1.8, 1.5)):
        x, xdot, x_r, xdot_r, sigma, s0 = rng.normal(scale=0.1, size=(6, 3))
        alpha = 2.5
        e_list, edot_list = task_error("position", 0.1, *(a.tolist() for a in (x, xdot, x_r, xdot_r)))
        out = np.array(law.values(t, e_list, edot_list, alpha,
                                  [0.0, 0.0, phase_tf, 0.75, 1.0], [0.0, *s0], sigma.tolist()))
        e, edot = x - x_r, xdot - xdot_r
        s = edot + alpha * e
        decay = np.exp(-3.0 * t) if t < phase_tf else np.exp(-3.0 * phase_tf - 50.0 * (t - phase_tf))
        s_d = s0 * decay
        expected = np.concatenate([s - s_d + 5.0 * sigma, e, edot, s, s_d, np.tanh((s - s_d) / 0.01)])
        np.testing.assert_allclose(out, expected, rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("nv, damping", [(3, 0.0), (3, 0.05), (5, 0.0), (5, 0.05)])
def test_smc_torque_is_minus_K_pinv_J_s_x(nv, damping):
    """``smc_torque`` (fused system, block and SMC baseline) against τ = −K J⁺ s_x (eq. 18) with
    numpy: J⁺ = Jᵀ(JJᵀ + λ²I)⁻¹ (λ = 0: the inverse or the minimum-norm pseudoinverse); it takes
    lists and arrays alike and gives the same floats."""
    from ptint_drake.controllers.ptsmc.law import smc_torque

    rng = np.random.default_rng(nv + int(100 * damping))
    K = rng.uniform(10.0, 60.0, nv)
    for _ in range(20):
        J = rng.normal(size=(3, nv))
        s_x = rng.normal(size=3)
        pinv = J.T @ np.linalg.inv(J @ J.T + damping**2 * np.eye(3))
        tau = smc_torque(K.tolist(), J.tolist(), s_x.tolist(), damping)
        np.testing.assert_allclose(tau, -K * (pinv @ s_x), rtol=1e-9, atol=1e-12)
        np.testing.assert_array_equal(smc_torque(K, J, s_x, damping), tau)


def _lean_and_general(J, b, damping):
    """``pinv_solve_into`` without ``general`` (its return value, ``out`` after it) and with it."""
    from ptint_drake.controllers.ptsmc.law import pinv_solve_into, pinv_work_size

    J = np.ascontiguousarray(J, dtype=float)
    work = np.empty(pinv_work_size(*J.shape))
    lean, general = np.full(J.shape[1], 7.0), np.full(J.shape[1], 7.0)
    solved = pinv_solve_into(J, b, damping, lean, work)
    assert pinv_solve_into(J, b, damping, general, work, True)
    return solved, lean, general


@pytest.mark.parametrize("rows, nv, damping",
                         [(3, 3, 0.0), (3, 4, 0.0), (3, 3, 0.05), (6, 6, 0.0), (6, 5, 0.0)])
def test_the_lean_solve_is_the_general_one_where_it_solves(rows, nv, damping):
    """The kernels a run calls leave numpy's solvers out (``pinv_solve_into`` without
    ``general``): where they solve, the bits of the general solve."""
    rng = np.random.default_rng(rows * 10 + nv)
    for _ in range(20):
        J, b = rng.normal(size=(rows, nv)), rng.normal(size=rows)
        solved, lean, general = _lean_and_general(J, b, damping)
        assert solved
        np.testing.assert_array_equal(lean, general)


def test_the_lean_solve_leaves_what_needs_numpy_to_the_general_one():
    """A singular 3 × 3 J (Cramer's rule cannot), a rank-deficient 6-row J (Householder cannot),
    a damped 6-row solve and more than 8 joints: False and ``out`` untouched; the general solve
    gives ``pinv_solve``'s answer (numpy's least squares for the singular J)."""
    from ptint_drake.controllers.ptsmc.law import pinv_solve

    rng = np.random.default_rng(4)
    singular = np.array([[1.0, 2, 3], [2, 4, 6], [0, 1, 1]])
    deficient = rng.normal(size=(6, 6))
    deficient[:, 5] = deficient[:, 4]
    cases = [(singular, 0.0), (deficient, 0.0), (rng.normal(size=(6, 6)), 0.05),
             (rng.normal(size=(3, 9)), 0.0)]
    for J, damping in cases:
        b = rng.normal(size=J.shape[0])
        solved, lean, general = _lean_and_general(J, b, damping)
        assert not solved and np.all(lean == 7.0)
        np.testing.assert_array_equal(general, pinv_solve(np.ascontiguousarray(J), b, damping))
    np.testing.assert_allclose(_lean_and_general(singular, np.ones(3), 0.0)[2],
                               np.linalg.lstsq(singular, np.ones(3), rcond=None)[0], atol=1e-12)
