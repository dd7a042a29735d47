"""estimator: auto — the IMM filter of systems/estimation/imm.py, and the retired measurement options."""

import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.simulation.scenario import ScenarioError, parse_scenario
from ptint_drake.systems.estimation import imm_kernels as imm
from ptint_drake.systems.estimation.imm import MODELS, AdaptiveTargetEstimator
from ptint_drake.systems.estimation.kalman import AddCameraEstimators
from ptint_drake.systems.perception.camera import MeasurementConfig, validate_measurement
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import BallisticTarget, LinearTarget, SinusoidTarget, TargetSource

CURVE = SinusoidTarget([0.24, 0.0, 0.3], [0.1] * 3, 1.5, [0.0, np.pi / 2, 0.0])  # paper eq. 28
TRACKS = {
    "cv": LinearTarget([0.3, -0.12, 0.2], [0.03, 0.08, -0.01]),
    "turn": CURVE,
    "fall": BallisticTarget([0.2, 0.0, 0.05], [0.05, 0.15, 2.5], [0.0, 0.0, -9.81]),
}


def _feed(target, config, t_end, t_start=0.0):
    """Camera samples of ``target`` at the camera's rate, fed to ``step`` at their visibility
    times; yields (t_est, state) after each update."""
    f = AdaptiveTargetEstimator(config=config)
    state = (np.zeros(4), None, None, None)
    rng = np.random.default_rng(3)
    for k in range(int(round(t_start * config.rate_hz)), int(t_end * config.rate_hz) + 1):
        t_k = k / config.rate_hz
        z = target.evaluate(t_k)[0:3] + rng.normal(0.0, config.noise_std, 3)
        result = f.step(*state, t_k + config.latency, np.array([t_k, *z, 1.0]))
        if result is not None:
            state = result
        yield state


def _combined(state):
    meta, X, _, mu = state
    return meta[1], mu @ X


@pytest.mark.parametrize("kind", sorted(TRACKS))
def test_converges_on_noiseless_tracks(kind):
    """No noise: the combined estimate of position, velocity, acceleration meets the track."""
    target = TRACKS[kind]
    config = MeasurementConfig(rate_hz=60.0 if kind == "fall" else 30.0, latency=0.02)
    t_end = 0.4 if kind == "fall" else 6.0
    for state in _feed(target, config, t_end):
        pass
    t_est, x = _combined(state)
    truth = target.evaluate(t_est)
    assert np.linalg.norm(x[0:3] - truth[0:3]) <= 1e-4
    assert np.linalg.norm(x[3:6] - truth[3:6]) <= 1e-2


@pytest.mark.parametrize("kind", sorted(TRACKS))
def test_probabilities_sum_to_one_and_move_to_the_right_model(kind):
    """A belt → cv, the paper's ellipse → turn, a throw → fall (from uniform μ at the start)."""
    target = TRACKS[kind]
    config = MeasurementConfig(noise_std=0.002, rate_hz=60.0 if kind == "fall" else 30.0, latency=0.02)
    history = [state[3] for state in _feed(target, config, 0.4 if kind == "fall" else 6.0)]
    for mu in history:
        assert mu.sum() == pytest.approx(1.0, abs=1e-12) and (mu >= 0).all()
    mu = history[-1]
    assert mu.argmax() == MODELS.index(kind) and mu.max() > 0.8, mu
    if kind == "turn":  # Ω learnt: ω = 1.5 rad/s
        assert history and np.sqrt(_last_omega(target, config)) == pytest.approx(1.5, rel=0.1)


def _last_omega(target, config):
    for state in _feed(target, config, 6.0):
        pass
    return state[1][MODELS.index("turn"), 9]


def test_covariances_stay_spd_through_dropouts():
    """A Drake run with a 0.5 s dropout: every model's P symmetric positive definite at every
    update, and the position variance grows while no sample comes."""
    config = MeasurementConfig(noise_std=0.002, latency=0.033, dropouts=[[1.0, 1.5]])
    builder = DiagramBuilder()
    schedule = Schedule([Segment(0.0, 2.5, 0.75)])
    truth = builder.AddSystem(TargetSource(schedule, [CURVE]))
    handles = AddCameraEstimators(builder, objects_port=truth.get_objects_output_port(),
                                  schedule=schedule, config=config, histories=[CURVE])
    simulator = Simulator(builder.Build())
    est = handles.filters[0]
    assert isinstance(est, AdaptiveTargetEstimator)
    context = est.GetMyContextFromRoot(simulator.get_mutable_context())
    variances = {}
    for t in np.arange(0.05, 2.5, 1 / 30):
        simulator.AdvanceTo(t)
        meta, X, Ps, mu = est.state(context)
        for P in Ps:
            np.testing.assert_allclose(P, P.T, atol=1e-15)
            assert np.linalg.eigvalsh(P).min() > 0.0
        variances[round(t, 3)] = mu @ Ps[:, 0, 0]
    during = [v for t, v in variances.items() if 1.1 < t < 1.5]
    assert all(b > a for a, b in zip(during, during[1:]))  # predict only: P grows
    assert variances[min(variances, key=lambda t: abs(t - 2.4))] < during[-1]


def test_state_is_named_and_output_layout_is_the_kalman_one():
    est = AdaptiveTargetEstimator(config=MeasurementConfig(noise_std=0.002))
    assert set(est.groups) == {"meta", "estimates", "covariances", "probabilities", "polynomial"}
    context = est.CreateDefaultContext()
    sizes = [context.get_discrete_state(est.groups[n]).size()
             for n in ("meta", "estimates", "covariances", "probabilities", "polynomial")]
    m = len(MODELS)
    assert sizes == [4, m * imm.N, m * imm.N * imm.N, m, 28]
    assert est.get_target_output_port().size() == 9
    np.testing.assert_array_equal(est.get_target_output_port().Eval(context), np.zeros(9))


def test_output_extrapolates_the_combined_estimate():
    """The output is [p + vΔt + aΔt²/2, v + aΔt, a] of χ̂ = Σ μⱼ χⱼ, bit for bit, from the
    ``polynomial`` stored at each update (and after priming)."""
    config = MeasurementConfig(noise_std=0.002, latency=0.02)
    prior = [(t, CURVE.evaluate(t)[0:3]) for t in (-0.2, -0.1667, -0.1333, -0.1)]
    est = AdaptiveTargetEstimator(config=config, prior=prior)
    context = est.CreateDefaultContext()
    est.get_measurement_input_port().FixValue(context, [0.01, *CURVE.evaluate(0.01)[0:3], 1.0])
    simulator = Simulator(est, context)
    for t in (0.0, 0.05):
        simulator.AdvanceTo(t)
        meta, X, _, mu = est.state(context)
        assert context.get_discrete_state(est.groups["polynomial"]).value()[0] == meta[1]
        dt = t - meta[1]
        combined = mu @ X
        p, v, a = combined[0:3], combined[3:6], combined[6:9]
        np.testing.assert_array_equal(est.get_target_output_port().Eval(context),
                                      np.concatenate([p + dt * v + (0.5 * dt * dt) * a, v + dt * a, a]))


def test_compiled_cycle_matches_the_numpy_reference():
    """Along 400 cycles (random Δ, 15 % without a sample, a turning belt that becomes a throw):
    from each state, the compiled mixing, the prediction of every model (by its code) and the
    correction equal ``_ReferenceIMM``'s to 1e-12 (relative to each array's largest entry), and
    a whole cycle to 1e-7; left to run on their own the two stay within 1e-6.  The looser
    bounds are the filter's, not the port's: ``_ReferenceIMM`` itself moves a cycle's P by
    ~4e-9 when χ moves by one ulp (Ω's forward-difference Jacobian, h = 1e-5, and the Joseph
    form's cancellation), and its own run by ~5e-8; on an AVX-512 processor (numpy's BLAS
    takes other kernels there) one cycle differed by 1.3e-8."""
    rng = np.random.default_rng(7)
    R = 4e-6

    def track(t):
        fall = 4.905 * (t - 5.0) ** 2 if t > 5.0 else 0.0
        return np.array([0.24 + 0.1 * np.sin(1.5 * t), 0.1 * np.cos(1.5 * t) + 0.05 * t, 0.3 - fall])

    def close(ours, ref, tol):
        for a, b in zip(ours, ref):
            np.testing.assert_allclose(a, b, rtol=0.0, atol=tol * np.abs(b).max())

    ours = imm.initial_state(track(0.0), R)
    theirs = _ReferenceIMM.initial_state(track(0.0), R)
    close(ours, theirs, 0.0)
    t = 0.0
    for _ in range(400):
        dt = rng.uniform(0.005, 0.05)
        t += dt
        z = track(t) + rng.normal(0.0, 0.002, 3)
        sample = rng.uniform() > 0.15
        X0, P0, c = _ReferenceIMM.mix(*ours, dt)
        close(imm.mix(*ours, dt), (X0, P0, c), 1e-12)
        for j, model in enumerate(MODELS):
            predicted = _ReferenceIMM.predict(model, X0[j], P0[j], dt)
            close(imm.predict_model(j, X0[j], P0[j], dt), predicted, 1e-12)
            close(imm.correct(*predicted, z, R), _ReferenceIMM.correct(*predicted, z, R), 1e-12)
        one_step = _ReferenceIMM.imm_cycle(*ours, dt, z if sample else None, R)
        ours = imm.imm_cycle(*ours, dt, z if sample else imm.NO_SAMPLE, R)
        theirs = _ReferenceIMM.imm_cycle(*theirs, dt, z if sample else None, R)
        close(ours, one_step, 1e-7)
        close(ours, theirs, 1e-6)
    assert ours[2].sum() == pytest.approx(1.0, abs=1e-12)


class _ReferenceIMM:
    """The IMM cycle as plain numpy, as systems/estimation/imm.py had it before it was compiled (string
    model names, ``np.linalg.inv``/``slogdet``, ``einsum``): the yardstick of the kernels."""

    @staticmethod
    def initial_state(z, R):
        x = np.concatenate([z, np.zeros(6), [imm.OMEGA0]])
        P = np.diag([R] * 3 + [imm.V0 ** 2] * 3 + [imm.A0 ** 2] * 3 + [imm.OMEGA_SD0 ** 2])
        return np.tile(x, (4, 1)), np.tile(P, (4, 1, 1)), np.full(4, 0.25)

    @staticmethod
    def per_axis(block):
        k = block.shape[0]
        out = np.zeros((3 * k, 3 * k))
        for axis in range(3):
            out[axis::3, axis::3] = block
        return out

    @classmethod
    def axis_block(cls, omega2, dt):
        x = omega2 * dt * dt
        if x < 1.0e-4:
            s = dt * (1.0 - x / 6.0 + x * x / 120.0)
            c = 1.0 - x / 2.0 + x * x / 24.0
            r = dt * dt * (0.5 - x / 24.0 + x * x / 720.0)
        else:
            w = math.sqrt(omega2)
            s, c, r = math.sin(w * dt) / w, math.cos(w * dt), (1.0 - math.cos(w * dt)) / omega2
        return cls.per_axis(np.array([[1.0, s, r], [0.0, c, s], [0.0, -omega2 * s, c]]))

    @classmethod
    def jerk(cls, dt, q):
        d2, d3 = dt * dt, dt * dt * dt
        return cls.per_axis(q * np.array([[d3 * d2 / 20.0, d2 * d2 / 8.0, d3 / 6.0],
                                          [d2 * d2 / 8.0, d3 / 3.0, d2 / 2.0],
                                          [d3 / 6.0, d2 / 2.0, dt]]))

    @classmethod
    def predict(cls, model, x, P, dt):
        F, Q = np.eye(10), np.zeros((10, 10))
        d2 = dt * dt
        if model in ("cv", "fall"):
            F[0:9, 0:9] = cls.per_axis(np.array([[1.0, dt, 0.0], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]))
            F[:, 6:9] = 0.0
            q = imm.Q_CV if model == "cv" else imm.Q_FALL
            Q[0:6, 0:6] = cls.per_axis(q * np.array([[d2 * dt / 3.0, d2 / 2.0], [d2 / 2.0, dt]]))
            Q[6:9, 6:9] = imm.A_CV ** 2 * np.eye(3)
            x_new = F @ x
            if model == "fall":
                x_new[0:9] += np.concatenate([0.5 * d2 * imm.GRAVITY, dt * imm.GRAVITY, imm.GRAVITY])
        elif model == "ca":
            F[0:9, 0:9] = cls.per_axis(np.array([[1.0, dt, 0.5 * d2], [0.0, 1.0, dt], [0.0, 0.0, 1.0]]))
            Q[0:9, 0:9] = cls.jerk(dt, imm.Q_CA)
            x_new = F @ x
        else:
            omega2 = min(max(x[9], 0.0), imm.OMEGA_MAX)
            F[0:9, 0:9] = cls.axis_block(omega2, dt)
            h = 1.0e-5 * max(1.0, omega2)
            F[0:9, 9] = (cls.axis_block(omega2 + h, dt) - F[0:9, 0:9]) @ x[0:9] / h
            Q[0:9, 0:9] = cls.jerk(dt, imm.Q_TURN)
            Q[9, 9] = imm.Q_OMEGA * dt
            x_new = np.concatenate([F[0:9, 0:9] @ x[0:9], [omega2]])
        P_new = F @ P @ F.T + Q
        return x_new, 0.5 * (P_new + P_new.T)

    @staticmethod
    def correct(x, P, z, R):
        S = P[0:3, 0:3] + R * np.eye(3)
        y = z - x[0:3]
        S_inv = np.linalg.inv(S)
        K = P[:, 0:3] @ S_inv
        x = x + K @ y
        x[9] = min(max(x[9], 0.0), imm.OMEGA_MAX)
        A = np.eye(10)
        A[:, 0:3] -= K
        P = A @ P @ A.T + R * (K @ K.T)
        loglik = -0.5 * (y @ S_inv @ y + np.linalg.slogdet(S)[1] + 3.0 * math.log(2.0 * math.pi))
        return x, 0.5 * (P + P.T), loglik

    @staticmethod
    def mix(X, Ps, mu, dt):
        stay = math.exp(-max(dt, 0.0) / imm.SOJOURN)
        Pi = np.full((4, 4), (1.0 - stay) / 3) + (stay - (1.0 - stay) / 3) * np.eye(4)
        c = Pi.T @ mu
        W = Pi * mu[:, None] / c[None, :]
        X0, P0 = W.T @ X, np.empty_like(Ps)
        for j in range(4):
            D = X - X0[j]
            P0[j] = np.einsum("i,ikl->kl", W[:, j], Ps) + (D.T * W[:, j]) @ D
        return X0, P0, c

    @classmethod
    def imm_cycle(cls, X, Ps, mu, dt, z, R):
        if z is None:  # the coast: each model alone, μ held
            pairs = [cls.predict(model, X[j], Ps[j], dt) for j, model in enumerate(MODELS)]
            return np.array([x for x, _ in pairs]), np.array([P for _, P in pairs]), mu.copy()
        X0, P0, c = cls.mix(X, Ps, mu, dt)
        logs = np.zeros(4)
        for j, model in enumerate(MODELS):
            X0[j], P0[j] = cls.predict(model, X0[j], P0[j], dt)
            if z is not None:
                X0[j], P0[j], logs[j] = cls.correct(X0[j], P0[j], z, R)
        logw = np.log(np.maximum(c, 1e-300)) + logs
        w = np.exp(logw - logw.max())
        return X0, P0, w / w.sum()


@pytest.mark.parametrize("measurement, field, hint", [
    ("{estimator: none, noise_std: 0.002}", "measurement.noise_std", "retired"),
    ("{estimator: none, latency: 0.03}", "measurement.latency", "retired"),
    ("{estimator: none, dropouts: [[0.1, 0.2]]}", "measurement.dropouts", "retired"),
    ("{process_noise: 0.01}", "measurement.process_noise", "kalman_cv"),
    ("{estimator: auto, process_noise: 0.01}", "measurement.process_noise", "remove process_noise"),
])
def test_retired_options_are_one_line_errors(measurement, field, hint):
    text = _SCENARIO + f"measurement: {measurement}\n"
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, "x")
    message = str(info.value)
    assert message.startswith(field) and hint in message and "\n" not in message


def test_measurement_defaults():
    assert parse_scenario(_SCENARIO, "x").measurement is None  # the analytic target
    m = parse_scenario(_SCENARIO + "measurement: {noise_std: 0.002}\n", "x").measurement
    assert m.estimator == "auto" and m.compensate_latency and m.process_noise is None
    validate_measurement(MeasurementConfig(estimator="kalman_cv", process_noise=1e-6))


@pytest.mark.parametrize("throw, field", [
    ("{start: [0.25, 0.0, 0.3], velocity: [0, 0, 0], release: 0.5}", "interceptions[0].start"),
    ("{start: [0.25, 0.0, 0.3], velocity: [0, 0, 0]}", "interceptions[0].tf"),
    ("{start: [0.25, 0.0], velocity: [0, 0, 0]}", "interceptions[0].target.ballistic.start"),
])
def test_bad_throws_are_one_line_errors(throw, field):
    text = _SCENARIO.replace("{linear: {start: [0.3, -0.12, 0.2], velocity: [0.0, 0.08, 0.0]}}",
                             f"{{ballistic: {throw}}}")
    with pytest.raises(ScenarioError) as info:
        parse_scenario(text, "x")
    assert str(info.value).startswith(field) and "\n" not in str(info.value)


def test_ballistic_target_is_held_before_release_and_unseen_by_the_camera():
    b = BallisticTarget([0.2, 0.0, 0.1], [0.0, 0.1, 2.0], [0.0, 0.0, -9.81], release=0.5)
    np.testing.assert_array_equal(b.evaluate(0.2), np.concatenate([[0.2, 0.0, 0.1], np.zeros(9)]))
    np.testing.assert_allclose(b.evaluate(0.7)[0:3], [0.2, 0.02, 0.1 + 0.4 - 0.5 * 9.81 * 0.04])
    from ptint_drake.systems.perception.camera import Camera  # noqa: PLC0415
    camera = Camera(config=MeasurementConfig(rate_hz=30.0), history=b)
    assert camera.dropped(0.4) and not camera.dropped(0.5) and camera.pre_run_samples() == []


_SCENARIO = """duration: 2.0
robot: {model: rvm1, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0]}
interceptions:
  - {start: 0.0, tf: 1.0, beta: 0.75,
     target: {linear: {start: [0.3, -0.12, 0.2], velocity: [0.0, 0.08, 0.0]}}}
"""
