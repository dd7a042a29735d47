"""What every camera estimator shares: when it updates and where it starts (``SampledEstimator``).

``kalman.TargetKalmanFilter``, ``imm.AdaptiveTargetEstimator`` and
``rotation_estimator.RotationEstimator`` differ only in their model (how an estimate starts
from a first sample, is predicted and is corrected); the rule below is this base class's.

Timing.  The estimator updates periodically at ``rate_hz`` with offset ``latency``, i.e.
exactly when the camera's sample k becomes visible (see ``camera``).  At an update at
time t, with the camera's sample [stamp, z, valid] (z: a position, or a rotation row-major):

- a new valid sample (stamp later than the last one consumed): predict to its
  measurement time and correct; the measurement time is the stamp with
  ``compensate_latency`` and the update time t without (the delay is then not known
  to the filter: it treats the sample as taken when it sees it);
- no new sample (a dropout): predict only, to t − latency (compensating) or t, so the
  covariance grows;
- the first valid sample initialises the estimate from it (the model's rule: for the
  Kalman filter χ = [z, 0(, 0)], P₀ = diag(R, V0², A0²));
- before the first sample nothing changes.

Priming (``prior``).  In a scenario every object is on its conveyor before its segment
starts, so the camera has had it in view before the run (``measurement.prior_window``,
default 1 s; ``Camera`` with a ``history``): the samples t_k = k/rate < 0 that were
visible by t = 0 (t_k + L ≤ 0) are consumed, in order, at their visibility times by the
same update rule, and the result is the estimator's *default* state.  So at t = 0 the
estimate is already a filtered one (not zeros, not one raw sample), which matters because
the interceptor captures s(t0) from it at initialisation.  Nothing else changes: during
the run sample k is still seen at t_k + L, and an estimator without a prior outputs its
"nothing seen" value until its first sample.

State in the context: discrete state groups (``groups``: name → index), ``meta`` =
[initialised, t_est, last stamp consumed, t of the last update] first, then the model's
(their shapes are those of ``_initial_estimate``), then any groups ``_derived`` from the
state (stored at each update so that an output only reads them).
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.systems.perception.camera import TIME_TOL, MeasurementConfig, validate_measurement

META_SIZE = 4  # [initialised, t_est, last stamp consumed, t of the last update]


class SampledEstimator(LeafSystem):
    """Base of the camera estimators: the camera-sample timing rule and the priming of the
    module docstring, the state groups in the context and the periodic update.

    A subclass calls ``__init__`` (which declares the input port ``input_name``, the camera's
    [stamp, z, valid] of ``input_size``), sets what its model needs, then calls
    ``_declare_state(names, prior)``; it implements ``_initial_estimate`` (the estimate before
    any sample, also its shapes), ``_first_estimate(z)``, ``_corrected(estimate, Δ, z)``
    (predicted over Δ, then corrected with z) and ``_predicted(estimate, Δ)``; ``_derived``
    (optional) names more groups computed from a state.
    """

    def __init__(self, *, config: MeasurementConfig, input_name: str, input_size: int):
        super().__init__()
        validate_measurement(config)
        self._latency = float(config.latency)
        self._compensate = bool(config.compensate_latency)
        self._period = 1.0 / config.rate_hz
        self._valid = input_size - 1
        self._z_in = self.DeclareVectorInputPort(input_name, input_size)

    def _declare_state(self, names: tuple[str, ...], prior) -> None:
        """Declare ``meta`` and the groups ``names`` with the primed state as their default
        (``_prior_state``), the ``_derived`` groups, and the update at the camera's instants."""
        state = self._prior_state(prior)
        self._names = ("meta", *names)
        self._shapes = tuple(np.shape(value) for value in state)
        self.groups = {name: self.DeclareDiscreteState(np.ravel(value))
                       for name, value in zip(self._names, state)}
        for name, value in self._derived(state).items():
            self.groups[name] = self.DeclareDiscreteState(value)
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, self._latency, self._update)

    def state(self, context) -> tuple:
        """(meta, *estimate) from a context (copies, in the shapes of ``_initial_estimate``)."""
        return tuple(context.get_discrete_state(self.groups[name]).value().copy().reshape(shape)
                     for name, shape in zip(self._names, self._shapes))

    def step(self, meta: np.ndarray, *args) -> tuple | None:
        """``step(meta, *estimate, t, z)``: one update at time t with the camera's output z:
        (meta, *estimate) after it, or None when nothing changes (no sample seen yet).  The
        rule of the module docstring."""
        *estimate, t, z = args
        initialised, t_est, last_stamp, _ = meta
        stamp = z[0]
        if z[self._valid] > 0.5 and (initialised < 0.5 or stamp > last_stamp + TIME_TOL):
            t_meas = stamp if self._compensate else t
            if initialised < 0.5:
                estimate = self._first_estimate(z)
            else:
                estimate = self._corrected(tuple(estimate), max(t_meas - t_est, 0.0), z)
            return (np.array([1.0, t_meas, stamp, t]), *estimate)
        if initialised < 0.5:
            return None
        t_pred = t - self._latency if self._compensate else t
        estimate = self._predicted(tuple(estimate), max(t_pred - t_est, 0.0))
        return (np.array([1.0, max(t_pred, t_est), last_stamp, t]), *estimate)

    def _update(self, context, discrete_state) -> None:
        result = self.step(*self.state(context), context.get_time(), self._z_in.Eval(context))
        if result is None:
            return
        for name, value in zip(self._names, result):
            discrete_state.get_mutable_vector(self.groups[name]).SetFromVector(np.ravel(value))
        for name, value in self._derived(result).items():
            discrete_state.get_mutable_vector(self.groups[name]).SetFromVector(value)

    def _prior_state(self, prior) -> tuple:
        """The state at t = 0 after the pre-run samples [(t_k, z_k), …] (oldest first), each
        consumed at the time it became visible, t_k + latency ≤ 0, by ``step``."""
        state = (np.zeros(META_SIZE), *self._initial_estimate())
        for t_k, z_k in prior or []:
            t_seen = t_k + self._latency
            if t_seen > TIME_TOL:
                raise ValueError(f"prior: a sample taken at {t_k} s is not visible before t = 0")
            result = self.step(*state, t_seen, np.array([t_k, *np.ravel(z_k), 1.0]))
            if result is not None:
                state = result
        return state

    def _derived(self, state: tuple) -> dict:
        """Groups computed from a state (meta, *estimate), stored with it: none by default."""
        return {}

    def _initial_estimate(self) -> tuple:
        """The estimate before any sample (its arrays' shapes are the groups' shapes)."""
        raise NotImplementedError

    def _first_estimate(self, z: np.ndarray) -> tuple:
        """The estimate from the first valid sample z = [stamp, …, valid]."""
        raise NotImplementedError

    def _corrected(self, estimate: tuple, dt: float, z: np.ndarray) -> tuple:
        """The estimate predicted over dt, then corrected with the sample z."""
        raise NotImplementedError

    def _predicted(self, estimate: tuple, dt: float) -> tuple:
        """The estimate predicted over dt (no sample)."""
        raise NotImplementedError
