"""The target as a camera sees it: delayed and noisy (see ``scenario.MeasurementConfig``)."""

from __future__ import annotations

import numpy as np


class MeasuredTarget:
    """Wraps a target (``evaluate(t)`` → [x, ẋ, ẍ, x⃛]) and perturbs its position.

    x_meas(t) = x(t − L) + n(t); with latency compensation the delayed sample is
    extrapolated with the profile's own velocity and acceleration:
    x(t − L) + ẋ(t − L) L + ẍ(t − L) L²/2.  The derivatives are those of the
    delayed profile.  n is piecewise linear between N(0, std²) samples drawn at
    ``rate_hz`` (so the measured position stays continuous), reproducible by seed.
    """

    def __init__(self, target, duration: float, noise_std: float = 0.0, rate_hz: float = 30.0,
                 latency: float = 0.0, compensate_latency: bool = False, seed: int = 0):
        self._target = target
        self._latency = latency
        self._compensate = compensate_latency
        n = int(np.ceil(duration * rate_hz)) + 2
        self._noise_t = np.arange(n) / rate_hz
        self._noise = np.random.default_rng(seed).normal(0.0, noise_std, (n, 3)) if noise_std > 0 \
            else np.zeros((n, 3))

    def noise(self, t: float) -> np.ndarray:
        return np.array([np.interp(t, self._noise_t, self._noise[:, k]) for k in range(3)])

    def evaluate(self, t: float) -> np.ndarray:
        L = self._latency
        out = self._target.evaluate(t - L).copy()
        if self._compensate and L > 0.0:
            out[0:3] += out[3:6] * L + 0.5 * out[6:9] * L * L
        out[0:3] += self.noise(t)
        return out
