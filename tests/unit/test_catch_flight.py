"""The catch world's flight model and its fit (issue 46, ``worlds.catch.flight`` and
``flight_estimator``): the propagation is the truth's dragged flight (scipy's solution of the
same equation), the least-squares fit to noisy 60 Hz samples of a real throw predicts the catch
point within millimetres and learns the drag it was not told, and as a Drake system on the
camera's timing it gives the same fit."""

from __future__ import annotations

import numpy as np
import pytest

from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.worlds.catch import flight, thrower
from ptint_drake.worlds.catch.ball import BALL_MASS, drag_coefficient
from ptint_drake.worlds.catch.flight_estimator import FlightEstimator

START = np.array([0.58, -0.1, 0.72])  # about the hand's start point
C_TRUE = drag_coefficient() / BALL_MASS


def _samples(seed: int, until: float):
    th = thrower.throw(seed, START)
    sol = thrower.flight(np.array(th.launch), np.array(th.velocity), th.flight_time + 0.1)
    ts = np.arange(0.0, until, 1 / 60)
    zs = np.array([sol(t)[:3] for t in ts]) + np.random.default_rng(seed).normal(0.0, 0.003, (len(ts), 3))
    return th, sol, ts, zs


def test_the_propagation_is_the_dragged_flight_forward_and_back():
    th = thrower.throw(3, START)
    sol = thrower.flight(np.array(th.launch), np.array(th.velocity), 1.0)
    at = sol(0.4)
    states = flight.propagate(at[:3], at[3:], C_TRUE, 0.4, [0.0, 0.1, 0.55, 0.9])
    for t, s in zip([0.0, 0.1, 0.55, 0.9], states):
        assert np.allclose(s, sol(t), atol=1e-7)


def test_the_fit_predicts_the_catch_point_and_learns_the_drag():
    errors, drags, drag_free = [], [], []
    for seed in range(8):  # 0.05 s before each throw's aim time (the hand's catch is near it)
        th, sol, ts, zs = _samples(seed, thrower.throw(seed, START).flight_time - 0.05)
        truth = sol(th.flight_time)[:3]
        theta = flight.fit(ts, zs, 0.003)
        predicted = flight.propagate(theta[:3], theta[3:6], theta[6], ts[-1], [th.flight_time])[0, :3]
        errors.append(np.linalg.norm(predicted - truth))
        drags.append(theta[6])
        line = flight.first_guess(ts, zs)  # the same samples without drag: a parabola under g
        dt = th.flight_time - ts[-1]
        drag_free.append(np.linalg.norm(line[:3] + line[3:6] * dt + 0.5 * flight.GRAVITY * dt * dt - truth))
    assert np.median(errors) < 0.004 and np.max(errors) < 0.010
    assert 0.5 * C_TRUE < np.median(drags) < 1.5 * C_TRUE  # the prior's mean is 0
    assert np.median(drag_free) > 2 * np.median(errors)


def test_the_estimator_system_gives_the_fit_at_the_cameras_instants():
    th, sol, ts, zs = _samples(2, 0.5)
    est = FlightEstimator(config=MeasurementConfig(rate_hz=60.0, noise_std=0.003, latency=0.017))
    state = est.state(est.CreateDefaultContext())
    for t, z in zip(ts, zs):
        state = est.step(*state, t + 0.017, np.array([t, *z, 1.0])) or state
    context = est.CreateDefaultContext()
    for name, value in zip(("meta", "samples", "fit"), state):
        context.SetDiscreteState(est.groups[name], np.ravel(value))
    fit = est.fitted(context)
    assert fit[0] == len(ts) and fit[1] == ts[-1]
    assert np.allclose(fit[2:9], flight.fit(ts, zs, 0.003), atol=1e-6)
    context.SetTime(ts[-1] + 0.02)
    out = est.get_target_output_port().Eval(context)
    assert np.linalg.norm(out[0:3] - sol(ts[-1] + 0.02)[:3]) < 0.004
    assert flight.from_estimate(out) == pytest.approx(fit[8], rel=1e-9)
