"""systems/estimation/sampled_estimator.py: the camera-sample timing rule and the priming, written once and
used by the Kalman filter, the IMM and the rotation filter alike."""

import numpy as np
import pytest

from ptint_drake.systems.estimation.imm import AdaptiveTargetEstimator
from ptint_drake.systems.estimation.kalman import TargetKalmanFilter
from ptint_drake.systems.estimation.rotation_estimator import RotationEstimator
from ptint_drake.systems.estimation.sampled_estimator import SampledEstimator
from ptint_drake.systems.perception.camera import MeasurementConfig

CONFIG = MeasurementConfig(noise_std=0.002, rate_hz=30.0, latency=0.05, compensate_latency=True)
MAKERS = {
    "kalman": lambda prior=None: TargetKalmanFilter(config=CONFIG, model="ca", prior=prior),
    "imm": lambda prior=None: AdaptiveTargetEstimator(config=CONFIG, prior=prior),
    "rotation": lambda prior=None: RotationEstimator(config=CONFIG, prior=prior),
}


def _sample(kind: str, t_k: float):
    """A sample taken at t_k: a position on a line, or a rotation about z."""
    if kind == "rotation":
        c, s = np.cos(0.2 * t_k), np.sin(0.2 * t_k)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return np.array([0.3, 0.1 * t_k, 0.2])


def _row(kind: str, t_k: float, valid: float = 1.0) -> np.ndarray:
    return np.array([t_k, *np.ravel(_sample(kind, t_k)), valid])


@pytest.mark.parametrize("kind", sorted(MAKERS))
def test_every_estimator_follows_the_one_timing_rule(kind):
    """Nothing before the first valid sample; a new sample: meta [1, stamp, stamp, t] (latency
    compensated); the same stamp again (a dropout): predicted to t − L, stamp kept."""
    f = MAKERS[kind]()
    assert isinstance(f, SampledEstimator)
    state = f.state(f.CreateDefaultContext())
    np.testing.assert_array_equal(state[0], np.zeros(4))
    assert f.step(*state, 0.05, _row(kind, 0.0, valid=0.0)) is None
    state = f.step(*state, 0.05, _row(kind, 0.0))
    np.testing.assert_array_equal(state[0], [1.0, 0.0, 0.0, 0.05])
    state = f.step(*state, 0.05 + 1 / 30, _row(kind, 1 / 30))
    np.testing.assert_array_equal(state[0], [1.0, 1 / 30, 1 / 30, 0.05 + 1 / 30])
    state = f.step(*state, 0.05 + 2 / 30, _row(kind, 1 / 30))  # no new sample
    np.testing.assert_allclose(state[0], [1.0, 2 / 30, 1 / 30, 0.05 + 2 / 30], rtol=0, atol=1e-15)


@pytest.mark.parametrize("kind", sorted(MAKERS))
def test_prior_is_the_default_state_after_the_same_steps(kind):
    """The primed default state equals the samples fed to ``step`` at their visibility times;
    a sample not visible by t = 0 is refused."""
    times = [-0.3 + k / 30 for k in range(7)]  # t_k + 0.05 ≤ 0
    prior = [(t_k, _sample(kind, t_k)) for t_k in times]
    primed = MAKERS[kind](prior)
    fed = MAKERS[kind]()
    state = fed.state(fed.CreateDefaultContext())
    for t_k in times:
        state = fed.step(*state, t_k + 0.05, _row(kind, t_k))
    for a, b in zip(primed.state(primed.CreateDefaultContext()), state):
        np.testing.assert_array_equal(a, np.reshape(b, np.shape(a)))
    with pytest.raises(ValueError, match=r"^prior: "):
        MAKERS[kind]([(-0.01, _sample(kind, -0.01))])
