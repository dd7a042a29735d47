"""The catch world's ball estimator (issue 46): the dragged flight of ``flight`` fitted to every
camera sample seen so far, as a Drake system on the camera estimators' timing
(``systems.estimation.sampled_estimator``: an update when a sample becomes visible, the
sample's stamp its measurement time).

Why not ``auto`` alone: the IMM's free-fall model has no drag, so late in a flight, when the
drag has bent the path by centimetres, it weighs in its other models; measured offline on throws
0–23 (3 mm, 60 Hz, 17 ms), the catch point it predicts 0.05 s before the catch is 5.0 mm off
(median; max 9.1), and 42 mm (max 344) at 0.15 s.  The fit of the flight's own model (seven
numbers over all the samples) gives 2.2 mm (max 7.6) and 38 mm (max 69): ``docs/catch.md``.

Output ``target`` (9) = [p + vΔt + ½aΔt², v' = v + aΔt, g − c|v'|v'] of the fitted [p, v] at the
newest sample's time, a = g − c|v|v, Δt = t − that time (the same layout as the other
estimators; the acceleration is the model's at v', so that ``flight.from_estimate`` recovers c
from the output at any time).  With fewer than ``MIN_SAMPLES`` samples: the
newest sample, at rest.  The buffer holds ``CAPACITY`` samples (1.6 s at 60 Hz); later samples
are not taken (the catch is over by then).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.config.measurement import MeasurementConfig
from ptint_drake.systems.estimation.sampled_estimator import SampledEstimator
from ptint_drake.worlds.catch import flight

CAPACITY = 96
MIN_SAMPLES = 4


class FlightEstimator(SampledEstimator):
    """The dragged flight fitted to the camera's samples (module docstring).  Input
    ``measurement`` (5): a ``Camera``'s [stamp, x, y, z, valid]; output ``target`` (9)."""

    def __init__(self, *, config: MeasurementConfig):
        super().__init__(config=config, input_name="measurement", input_size=5)
        self._sigma = max(float(config.noise_std), 1e-4)
        self._declare_state(("samples", "fit"), None)
        ticket = {self.time_ticket(), self.xd_ticket()}
        self._target_out = self.DeclareVectorOutputPort(
            "target", 9, lambda c, o: o.SetFromVector(self._target(c)), prerequisites_of_calc=ticket)

    def get_measurement_input_port(self):
        return self._z_in

    def get_target_output_port(self):
        return self._target_out

    def _initial_estimate(self) -> tuple:
        return np.zeros((CAPACITY, 4)), np.zeros(9)

    def _first_estimate(self, z: np.ndarray) -> tuple:
        samples, fit = self._initial_estimate()
        samples[0] = z[0:4]
        fit[0:5] = [1.0, z[0], *z[1:4]]
        return samples, fit

    def _corrected(self, estimate: tuple, dt: float, z: np.ndarray) -> tuple:
        samples, fit = estimate[0].copy(), estimate[1].copy()
        n = int(fit[0])
        if n >= CAPACITY:
            return samples, fit
        samples[n] = z[0:4]
        n += 1
        ts, zs = samples[:n, 0], samples[:n, 1:4]
        if n < MIN_SAMPLES:
            theta = np.concatenate([zs[-1], np.zeros(4)])
        else:
            guess = flight.moved(fit[2:9], fit[1], ts[-1]) if n > MIN_SAMPLES else None
            theta = flight.fit(ts, zs, self._sigma, guess)
        return samples, np.concatenate([[n, ts[-1]], theta])

    def _predicted(self, estimate: tuple, dt: float) -> tuple:
        return estimate

    def fitted(self, context) -> np.ndarray:
        """[samples used, t_ref, p, v, c] of the newest fit (zeros before the first sample)."""
        return context.get_discrete_state(self.groups["fit"]).value().copy()

    def _target(self, context) -> np.ndarray:
        fit = context.get_discrete_state(self.groups["fit"]).value()
        if fit[0] < 1.0:
            return np.zeros(9)
        p, v, c = fit[2:5], fit[5:8], fit[8]
        a = flight.acceleration(v, c) if fit[0] >= MIN_SAMPLES else np.zeros(3)
        dt = context.get_time() - fit[1]
        v_t = v + a * dt
        a_t = flight.acceleration(v_t, c) if fit[0] >= MIN_SAMPLES else a
        return np.concatenate([p + v * dt + 0.5 * a * dt * dt, v_t, a_t])
