"""Target estimation from camera samples (systems/estimation/kalman.py)."""

import numpy as np
import pytest
from pydrake.math import DiscreteAlgebraicRiccatiEquation
from pydrake.systems.analysis import Simulator
from pydrake.systems.estimators import DiscreteTimeSteadyStateKalmanFilter
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import Sine, TrajectorySource, VectorLogSink
from pydrake.trajectories import PiecewisePolynomial

from ptint_drake.systems.estimation.kalman import (AddCameraEstimators, TargetKalmanFilter,
                                                   process_covariance, transition)
from ptint_drake.systems.estimation.target_prediction import ActiveTargetSelector
from ptint_drake.systems.perception.camera import Camera, MeasurementConfig
from ptint_drake.systems.task.schedule import Schedule, Segment

START = np.array([0.3, -0.15, 0.15])
VELOCITY = np.array([0.05, 0.1, -0.02])
DURATION = 12.0


def _line(builder, start=START, velocity=VELOCITY):
    traj = PiecewisePolynomial.FirstOrderHold(
        [0.0, DURATION], np.column_stack([start, start + velocity * DURATION]))
    return builder.AddSystem(TrajectorySource(traj))


def _filter_diagram(config, model, source=_line, log_period=None):
    """source → Camera → TargetKalmanFilter (+ a logger of ``target`` if log_period)."""
    builder = DiagramBuilder()
    src = source(builder)
    camera = builder.AddSystem(Camera(config=config))
    kf = builder.AddSystem(TargetKalmanFilter(config=config, model=model))
    builder.Connect(src.get_output_port(0), camera.get_x_true_input_port())
    builder.Connect(camera.get_measurement_output_port(), kf.get_measurement_input_port())
    log = None
    if log_period:
        log = builder.AddSystem(VectorLogSink(9, publish_period=log_period))
        builder.Connect(kf.get_target_output_port(), log.get_input_port())
    diagram = builder.Build()
    sim = Simulator(diagram)
    return sim, kf, kf.GetMyContextFromRoot(sim.get_mutable_context()), log


def _line_truth(t):
    return START + VELOCITY * t


@pytest.mark.parametrize("model", ["cv", "ca"])
@pytest.mark.parametrize("latency, compensate", [(0.0, False), (0.07, True)])
def test_converges_on_noiseless_constant_velocity_track(model, latency, compensate):
    config = MeasurementConfig(latency=latency, compensate_latency=compensate, process_noise=0.01,
                               estimator=f"kalman_{model}")
    sim, kf, ctx, _ = _filter_diagram(config, model)
    for t in (2.0, 3.0 + 0.3 / 30.0, 4.0 + 0.9 / 30.0):  # at, just after and just before updates
        sim.AdvanceTo(t)
        out = kf.get_target_output_port().Eval(ctx)
        np.testing.assert_allclose(out[0:3], _line_truth(t), atol=1e-6)
        np.testing.assert_allclose(out[3:6], VELOCITY, atol=1e-6)
        np.testing.assert_allclose(out[6:9], 0.0, atol=1e-6)


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_uncompensated_latency_lags_by_latency(model):
    """Without compensation the estimate is the track delayed by L (a lag of v·L)."""
    latency = 0.07
    config = MeasurementConfig(latency=latency, compensate_latency=False)
    sim, kf, ctx, _ = _filter_diagram(config, model)
    t = 3.0 + 0.5 / 30.0
    sim.AdvanceTo(t)
    out = kf.get_target_output_port().Eval(ctx)
    np.testing.assert_allclose(out[0:3], _line_truth(t - latency), atol=1e-6)
    np.testing.assert_allclose(out[3:6], VELOCITY, atol=1e-6)


def test_output_continuous_between_updates_no_sample_rate_steps():
    """Logged at 1 kHz on a converged CV track, the output never steps at the 30 Hz updates."""
    config = MeasurementConfig(noise_std=0.0, latency=0.02, compensate_latency=True)
    sim, _, _, log = _filter_diagram(config, "cv", log_period=1.0e-3)
    sim.AdvanceTo(3.0)
    data = log.FindLog(sim.get_context())
    t, x = data.sample_times(), data.data()
    late = t > 1.0
    steps = np.linalg.norm(np.diff(x[0:3, late], axis=1), axis=0)
    assert np.max(steps) == pytest.approx(np.linalg.norm(VELOCITY) * 1e-3, rel=1e-4)
    np.testing.assert_allclose(x[0:3, late], START[:, None] + VELOCITY[:, None] * t[late], atol=1e-6)


def _curve(builder):
    return builder.AddSystem(Sine(np.full(3, 0.1), np.full(3, 1.5), np.array([0.0, np.pi / 2, 0.0])))


@pytest.mark.parametrize("model", ["cv", "ca"])
def test_latency_compensation_removes_lag(model):
    """On a CV track with L = 0.1 s: compensated error ~ 0, uncompensated = v·L."""
    errors = {}
    for compensate in (False, True):
        config = MeasurementConfig(noise_std=1e-4, latency=0.1, compensate_latency=compensate,
                                   seed=2, process_noise=1e-4, estimator=f"kalman_{model}")  # small q: a line
        sim, kf, ctx, _ = _filter_diagram(config, model)
        err = []
        for t in np.arange(4.0, 6.0, 0.0123):
            sim.AdvanceTo(t)
            err.append(kf.get_target_output_port().Eval(ctx)[0:3] - _line_truth(t))
        errors[compensate] = np.mean(np.linalg.norm(err, axis=1))
    lag = np.linalg.norm(VELOCITY) * 0.1
    assert errors[False] == pytest.approx(lag, rel=0.05)
    assert errors[True] < 0.05 * lag


def test_covariance_stays_spd_and_grows_in_dropout():
    config = MeasurementConfig(noise_std=1e-3, dropouts=[[2.0, 2.5]])
    sim, kf, ctx, _ = _filter_diagram(config, "ca", source=_curve)
    variances, times = [], np.arange(0.5, 3.5, 1.0 / 60.0)
    for t in times:
        sim.AdvanceTo(t)
        P = kf.state(ctx)[2]
        np.testing.assert_array_equal(P, P.T)
        assert np.min(np.linalg.eigvalsh(P)) > 0.0
        variances.append(P[0, 0])
        out_cov = kf.get_covariance_output_port().Eval(ctx).reshape(3, 3)
        assert np.min(np.linalg.eigvalsh(0.5 * (out_cov + out_cov.T))) > 0.0
    v = np.array(variances)
    in_dropout = (times > 2.05) & (times < 2.5)
    assert np.all(np.diff(v[in_dropout]) >= 0.0) and v[in_dropout][-1] > 10 * v[in_dropout][0]
    steady = (times > 1.0) & (times < 2.0)
    assert np.max(v[steady]) < 1e-6  # below R: the filter averages
    assert v[times > 3.0][-1] < 1.01 * np.max(v[steady])  # back to steady after the dropout


@pytest.mark.parametrize("model, q", [("cv", 0.01), ("cv", 1.0), ("ca", 0.01), ("ca", 1.0)])
def test_converged_gain_matches_drake_steady_state(model, q):
    """The time-varying filter's gain converges to the DARE gain (Drake's steady-state
    filter is the cross-check, not the filter)."""
    rate = 30.0
    config = MeasurementConfig(noise_std=1e-3, rate_hz=rate, process_noise=q, seed=1,
                               estimator=f"kalman_{model}")
    sim, kf, ctx, _ = _filter_diagram(config, model, source=_curve)
    sim.AdvanceTo(8.0)
    _, _, P_post = kf.state(ctx)
    T = 1.0 / rate
    F, Q, R = transition(model, T), process_covariance(model, T, q), kf.measurement_variance
    H = np.zeros((1, kf.order))
    H[0, 0] = 1.0
    K = kf.gain(F @ P_post @ F.T + Q)

    X = DiscreteAlgebraicRiccatiEquation(A=F.T, B=H.T, Q=Q, R=np.array([[R]]))  # a-priori P
    K_dare = (X @ H.T / (H @ X @ H.T + R)).ravel()
    np.testing.assert_allclose(K, K_dare, rtol=1e-6)
    L = DiscreteTimeSteadyStateKalmanFilter(F, H, Q, np.array([[R]]))  # predictor gain F K
    np.testing.assert_allclose(F @ K, L.ravel(), rtol=1e-6)


def test_state_layout_and_initialisation():
    config = MeasurementConfig(noise_std=0.002, rate_hz=10.0)
    kf = TargetKalmanFilter(config=config, model="ca")
    ctx = kf.CreateDefaultContext()
    assert [ctx.get_discrete_state(i).size() for i in range(3)] == [4, 9, 9]
    np.testing.assert_array_equal(kf.get_target_output_port().Eval(ctx), np.zeros(9))
    z = np.array([0.0, 0.1, 0.2, 0.3, 1.0])
    sim = Simulator(kf)
    ctx = sim.get_mutable_context()
    kf.get_measurement_input_port().FixValue(ctx, z)
    sim.AdvanceTo(0.01)  # the update at t = 0 consumes the sample
    meta, X, P = kf.state(ctx)
    np.testing.assert_array_equal(meta, [1.0, 0.0, 0.0, 0.0])
    np.testing.assert_array_equal(X, [[0.1, 0.2, 0.3], [0, 0, 0], [0, 0, 0]])
    np.testing.assert_allclose(P, np.diag([0.002**2, 1.0, 100.0]))
    np.testing.assert_allclose(kf.get_target_output_port().Eval(ctx), [0.1, 0.2, 0.3, *np.zeros(6)])
    sim.AdvanceTo(0.25)  # the same stamp again at 0.1 and 0.2: no new sample, predict only
    meta, X, P2 = kf.state(ctx)
    np.testing.assert_allclose(meta, [1.0, 0.2, 0.0, 0.2])
    assert np.all(np.diag(P2) > np.diag(P))


def test_unknown_model_is_rejected():
    with pytest.raises(ValueError, match=r"^model: "):
        TargetKalmanFilter(config=MeasurementConfig(), model="imm")


def test_selector_follows_schedule():
    schedule = Schedule([Segment(0.5, 0.2, 0.5), Segment(1.0, 0.5, 0.5)])
    sel = ActiveTargetSelector(schedule=schedule, count=2)
    ctx = sel.CreateDefaultContext()
    sel.GetInputPort("target_0").FixValue(ctx, np.arange(9.0))
    sel.GetInputPort("target_1").FixValue(ctx, -np.arange(9.0))
    for t, sign in ((0.0, 1), (0.7, 1), (0.999, 1), (1.0, -1), (5.0, -1)):
        ctx.SetTime(t)
        np.testing.assert_array_equal(sel.get_target_output_port().Eval(ctx), sign * np.arange(9.0))
    with pytest.raises(ValueError, match=r"^count: "):
        ActiveTargetSelector(schedule=schedule, count=3)


def test_add_camera_estimators_tracks_the_active_object():
    schedule = Schedule([Segment(0.0, 0.5, 0.75), Segment(2.0, 1.0, 0.75)])
    velocities = [np.array([0.0, 0.1, 0.0]), np.array([0.0, -0.1, 0.05])]
    builder = DiagramBuilder()
    sources = [_line(builder, START + i * 0.1, v) for i, v in enumerate(velocities)]
    config = MeasurementConfig(noise_std=1e-4, latency=0.03, compensate_latency=True,
                               estimator="kalman_cv", process_noise=1e-4)
    handles = AddCameraEstimators(builder, true_position_ports=[s.get_output_port(0) for s in sources],
                                  schedule=schedule, config=config)
    assert [c.get_name() for c in handles.cameras] == ["camera_0", "camera_1"]
    assert [f.get_name() for f in handles.filters] == ["target_filter_0", "target_filter_1"]
    diagram = builder.Build()
    sim = Simulator(diagram)
    for t, i in ((1.9, 0), (3.5, 1)):
        sim.AdvanceTo(t)
        out = handles.target_port.Eval(handles.selector.GetMyContextFromRoot(sim.get_context()))
        np.testing.assert_allclose(out[0:3], START + i * 0.1 + velocities[i] * t, atol=3e-4)
        np.testing.assert_allclose(out[3:6], velocities[i], atol=5e-3)
    # each object has its own noise stream (seed_offset = index)
    a, b = handles.cameras
    assert not np.allclose(a.sample(5, np.zeros(3)), b.sample(5, np.zeros(3)))
    with pytest.raises(ValueError, match=r"^measurement\.estimator: "):
        AddCameraEstimators(DiagramBuilder(), true_position_ports=[], schedule=schedule,
                            config=MeasurementConfig(estimator="none"))
