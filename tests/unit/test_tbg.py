"""Time base generator (SPEC 2.1-2.2): closed form vs ODE, exactness at tf, α."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import betaincinv, gamma

from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.tbg import (TimeBaseGenerator, alpha_gain, alpha_peak, gamma_gain,
                                          tbg_derivatives, tbg_profile, tbg_state)


@pytest.mark.parametrize("beta", [0.25, 0.5, 0.75, 0.9])
def test_gamma_matches_gamma_function_form(beta):
    tf = 1.5
    expected = gamma(1 - beta) ** 2 / (tf * gamma(2 - 2 * beta))
    assert gamma_gain(tf, beta) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("beta", [0.25, 0.5, 0.75, 0.9])
def test_closed_form_matches_ode(beta):
    """Integrate the TBG ODE tightly and compare with the closed form.

    ξ = 1 is an equilibrium, so the ODE starts from the closed form at a small τ0;
    it is integrated in y = ln η (η = 1 − ξ, η̇ = γ (ξη)^β) so that the tiny η of
    β ≥ 0.75 near the start keeps its relative precision.
    """
    tf = 1.5
    g = gamma_gain(tf, beta)
    tau0 = 1e-3 * tf
    eta0 = betaincinv(1 - beta, 1 - beta, tau0 / tf)
    t_eval = np.linspace(tau0, 0.98 * tf, 200)
    sol = solve_ivp(lambda t, y: [g * (-np.expm1(y[0])) ** beta * np.exp((beta - 1) * y[0])],
                    (tau0, 0.98 * tf), [np.log(eta0)], t_eval=t_eval, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    eta_ode = np.exp(sol.y[0])
    xi_closed = tbg_profile(t_eval, tf, beta)[0]
    eta_closed = betaincinv(1 - beta, 1 - beta, t_eval / tf)
    assert np.max(np.abs(eta_ode / eta_closed - 1)) < 1e-8
    assert np.max(np.abs((1 - eta_ode) - xi_closed)) < 1e-9


def test_beta_half_is_cos_squared():
    tf = 1.5
    tau = np.linspace(0, tf, 101)
    xi, xd, _, _ = tbg_profile(tau, tf, 0.5)
    np.testing.assert_allclose(xi, np.cos(np.pi * tau / (2 * tf)) ** 2, atol=1e-12)
    np.testing.assert_allclose(xd, -np.pi / (2 * tf) * np.sin(np.pi * tau / tf), atol=1e-12)
    assert gamma_gain(tf, 0.5) == pytest.approx(np.pi / tf)


@pytest.mark.parametrize("beta", [0.25, 0.5, 0.75, 0.9])
def test_exact_at_tf_and_zero_after(beta):
    tf = 1.2
    xi, xd, xdd, xddd = tbg_profile(np.array([0.0, 0.5 * tf, tf, tf + 0.3]), tf, beta)
    assert xi[0] == 1.0 and xd[0] == 0.0
    assert xi[1] == pytest.approx(0.5, abs=1e-12)  # symmetric: ξ(tf/2) = 1/2 for every β
    assert xi[2] == 0.0 and xi[3] == 0.0
    assert xd[2] == 0.0 and xd[3] == 0.0 and xdd[3] == 0.0 and xddd[3] == 0.0
    # decreasing (ξ̇ < 0 strictly; ξ rounds to 1.0 near the start for β ≥ 0.75)
    tau = np.linspace(1e-6, tf * (1 - 1e-9), 5000)
    xi_in, xd_in, _, _ = tbg_profile(tau, tf, beta)
    assert np.all(np.diff(xi_in) <= 0) and np.all(xd_in < 0)
    assert np.all((xi_in > 0) & (xi_in <= 1))


@pytest.mark.parametrize("beta", [0.75, 0.9])
def test_complement_is_precise_near_one(beta):
    """η = 1 − ξ must not vanish near the start (it underflows if computed as 1 − ξ)."""
    tf = 1.5
    tau = 1e-9
    xi, xd, _, _ = tbg_profile(tau, tf, beta)
    # ξ̇ ≈ −γ η^β with η ≈ (γ (1−β) τ)^(1/(1−β)) near the start
    g = gamma_gain(tf, beta)
    eta = (g * (1 - beta) * tau) ** (1 / (1 - beta))
    assert xd < 0
    assert -xd == pytest.approx(g * eta ** beta, rel=1e-3)


def test_derivatives_are_consistent():
    """ξ̇, ξ̈, ξ⃛ agree with finite differences of the closed form (β = 0.75)."""
    tf, beta, h = 1.5, 0.75, 1e-5
    for tau in (0.2, 0.6, 1.0, 1.3):
        f = [tbg_profile(tau + k * h, tf, beta) for k in (-1, 0, 1)]
        assert f[1][1] == pytest.approx((f[2][0] - f[0][0]) / (2 * h), rel=1e-6)
        assert f[1][2] == pytest.approx((f[2][1] - f[0][1]) / (2 * h), rel=1e-5)
        assert f[1][3] == pytest.approx((f[2][2] - f[0][2]) / (2 * h), rel=1e-4)


def test_alpha_zero_at_start_peaks_before_tf():
    tf, beta = 1.5, 0.75
    tau = tf * (1 - np.logspace(-12, 0, 3000))[::-1]
    xi, xd, _, _ = tbg_profile(tau, tf, beta)
    a = alpha_gain(xi, xd)
    assert a[0] == 0.0 and np.all(a >= 0)
    k = int(np.argmax(a))
    assert tau[k] < tf
    # SPEC 2.2 closed-form estimate of the peak, α0 γ β^β (1−β)^(1−β) δ^(β−1)
    est = gamma_gain(tf, beta) * beta**beta * (1 - beta) ** (1 - beta) * 1e-6 ** (beta - 1)
    assert alpha_peak(tf, beta) == pytest.approx(est, rel=0.02)


def test_leaf_system_restarts_each_segment_and_holds():
    sched = Schedule([Segment(0.0, 0.5, 0.75), Segment(0.8, 1.4, 0.5)])
    tbg = TimeBaseGenerator(sched, alpha_hold=20.0)
    ctx = tbg.CreateDefaultContext()
    expect = {0.25: (0, 1.0), 0.6: (0, 2.0), 0.8: (1, 1.0), 1.5: (1, 1.0), 2.5: (1, 2.0)}
    for t, (index, phase) in expect.items():
        ctx.SetTime(t)
        seg = tbg.get_segment_output_port().Eval(ctx)
        assert (seg[0], seg[4]) == (index, phase)
        xi = tbg.get_xi_output_port().Eval(ctx)
        alpha = tbg.get_alpha_output_port().Eval(ctx)[0]
        if phase == 2.0:
            assert xi[0] == 0.0 and alpha == 20.0
        else:
            s = sched[index]
            np.testing.assert_allclose(xi, tbg_profile(t - s.start, s.tf, s.beta))
    ctx.SetTime(0.8)  # restart: ξ back at 1, α back at 0
    assert tbg.get_xi_output_port().Eval(ctx)[0] == 1.0
    assert tbg.get_alpha_output_port().Eval(ctx)[0] == 0.0


def _paper_tbg(tau, tf, beta):
    """Eqs. 6-10 with numpy arrays: ξ = I⁻¹(1−β, 1−β; 1 − τ/tf), η = 1 − ξ taken directly as
    I⁻¹(1−β, 1−β; τ/tf), ξ̇ = −γ(ξη)^β and its time derivatives by the chain rule."""
    u = np.asarray(tau, dtype=float) / tf
    a, g = 1.0 - beta, gamma_gain(tf, beta)
    xi, eta = betaincinv(a, a, 1.0 - u), betaincinv(a, a, u)
    p = xi * eta
    xi_d = -g * p**beta
    xi_dd = g**2 * beta * (1.0 - 2.0 * xi) * p ** (2.0 * beta - 1.0)
    xi_ddd = -g**3 * beta * p ** (3.0 * beta - 2.0) * ((2.0 * beta - 1.0) * (1.0 - 2.0 * xi) ** 2 - 2.0 * p)
    return np.array([xi, xi_d, xi_dd, xi_ddd])


@pytest.mark.parametrize("beta", [0.25, 0.5, 0.75, 0.9])
def test_one_tbg_function_matches_the_paper_equations(beta):
    """``tbg_state`` — what the fused system and the TBG block both call — against a numpy
    reference of eqs. 6-10 and 13 inside the segment, and the fixed values before and after."""
    tf, start = 1.5, 0.2
    sched = Schedule([Segment(start, tf, beta)])
    times = start + tf * np.array([1e-9, 1e-4, 0.1, 0.3, 0.5, 0.75, 0.9, 0.999, 1 - 1e-9])
    tau = times - start  # as the schedule sees it
    reference = _paper_tbg(tau, tf, beta)
    for k, tk in enumerate(tau):
        row = tbg_state(sched, float(times[k]), epsilon=1e-6, delta=1e-6)
        assert row.shape == (10,)
        np.testing.assert_allclose(row[0:4], reference[:, k], rtol=1e-11, atol=1e-300)
        assert row[4] == pytest.approx(-(1 + 1e-6) * reference[1, k] / (reference[0, k] + 1e-6), rel=1e-11)
        assert row[5:].tolist() == [0.0, start, tf, beta, 1.0]
        # the array form is the same function, to the bit
        assert tbg_profile(np.array([tk]), tf, beta)[1][0] == row[1]
        assert tbg_derivatives(float(tk), tf, beta, gamma_gain(tf, beta)) == tuple(row[0:4])
    assert tbg_state(sched, 0.0).tolist() == [1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0]
    assert tbg_state(sched, start + tf, alpha_hold=7.0)[0:5].tolist() == [0.0, 0.0, 0.0, 0.0, 7.0]
    assert TimeBaseGenerator(sched).evaluate(start + 0.4).tolist() == tbg_state(sched, start + 0.4).tolist()


def test_schedule_gamma_is_gamma_gain():
    sched = Schedule([Segment(0.0, 1.5, 0.75), Segment(2.0, 0.9, 0.3)])
    assert [sched.gamma(i) for i in range(2)] == [gamma_gain(1.5, 0.75), gamma_gain(0.9, 0.3)]
