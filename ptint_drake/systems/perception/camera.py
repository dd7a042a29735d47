"""A camera that reports one object's position: sampled, noisy, late, sometimes missing.

What it models (``Camera``, one per object):

- sampling at a fixed rate: sample k is taken at t_k = k / rate_hz, k = 0, 1, …
  (a periodic discrete update; the first sample is at t = 0);
- measurement noise: z_k = x_true(t_k) + n_k, n_k ~ N(0, noise_std² I₃) i.i.d.,
  drawn from ``numpy.random.default_rng(seed + seed_offset)``; n_k depends only
  on k, so a run is reproducible and does not depend on how often the output is
  evaluated (nor on the dropouts: sample k always carries the same n_k);
- a fixed latency L: sample k becomes visible at t_k + L;
- dropouts: a sample whose time falls in a window ``from ≤ t_k < to`` is never
  delivered (the output keeps holding the last delivered sample); nor is a sample
  taken before the object can be seen (``history.visible_from``: a throw's release);
- the object was in view before the run (``prior_window`` W, with ``history``):
  given the object's true motion as a function of time, the camera has also taken
  the samples k = −1, −2, … with −W ≤ t_k < 0 (same rate, same latency, same
  dropout rule, noise from a second stream of the same seed: the samples k ≥ 0 are
  the same with or without a history).  Those taken at t_k ≤ −L were visible
  before the run; they fill the delay buffer at t = 0 (``pre_run_samples`` lists
  them for a filter to start from).  Without ``history`` (or W = 0) the camera has
  seen nothing before t = 0.

The output ``measurement`` = [stamp, x, y, z, valid] is the newest sample visible
at time t, held between samples (zero-order hold); ``stamp`` = t_k is the time it
was taken, ``valid`` = 0 until the first sample is visible (then [0, 0, 0, 0, 0]); with a
pre-run history the newest pre-run sample (stamp < 0) is visible from t = 0.

Orientation (``rotation=True``: the object carries one, issue 19).  Sample k also holds
the object's measured orientation Z_k = exp([n_k^R]×) R_true(t_k), a world-frame
perturbation by a rotation vector n_k^R ~ N(0, σ_R² I₃), σ_R = ``rot_noise_deg`` (default
DEFAULT_ROT_NOISE_DEG) in radians, drawn from the streams [seed + seed_offset, 2] (k ≥ 0)
and [seed + seed_offset, 3] (k < 0), so the position samples are the same with or without
it.  Same instants, latency and dropouts as the position; output ``measured_rotation`` =
[stamp, Z_k (row-major), valid] (11) of the same newest visible sample.

What it does not model: the optics (projection, field of view, occlusion by the
arm, calibration or hand–eye bias), noise that is correlated in time or
between axes, outliers, jitter of the sample times or of the latency, rolling
shutter and motion blur, and data association (each camera sees exactly one,
known object).

Timing (the point of the design).  The delay buffer — the last N delivered
samples, N = ⌈L·rate⌉ + 2, newest first — is the system's discrete state; the
output is computed from it and the time, so sample k appears exactly at
t_k + L.  A downstream discrete system updating at t_k + L (period 1/rate,
offset L, as ``TargetKalmanFilter`` does) reads the output *before* any update
at that instant and still sees sample k: for L > 0 sample k was stored by the
camera's update at t_k < t_k + L; for L = 0 (both updates at t_k) the output
computes the not-yet-stored sample k from the input ``x_true`` (direct
feedthrough, only when L = 0).  Event times are computed by Drake as
offset + k·period, so "visible at t" is tested as stamp + L ≤ t + TIME_TOL with
TIME_TOL = 1e-9 s, which absorbs round-off (≈1e-14 s at t = 100 s) and is far
below any sample period; latencies below TIME_TOL count as 0.  For L > 0 a no-op
periodic publish event at offset L makes the simulator stop at every t_k + L, so
no integration step straddles a change of the output.
"""

# No ``from __future__ import annotations``: yaml_load_typed needs real annotations.
import itertools
import math

import numpy as np
from pydrake.systems.framework import LeafSystem

from ptint_drake.config.measurement import SENSORS, MeasurementConfig
from ptint_drake.systems.perception.rgbd_camera import validate_camera
from ptint_drake.systems.task.orientation import rotation_from_vector

ESTIMATORS = ("auto", "kalman_cv", "kalman_ca", "none")
# the hand-set filters' process noise q when the scenario does not state one
DEFAULT_PROCESS_NOISE = 0.01
# deg, per axis: the orientation noise of a camera that measures one, when not stated
DEFAULT_ROT_NOISE_DEG = 1.0
# Tolerance (s) on event times: a sample is visible at t when stamp + latency <= t + TIME_TOL.
TIME_TOL = 1.0e-9
# Size of the blocks of noise drawn at once (noise of sample k = row k of one stream).
_NOISE_BLOCK = 1024


def _field_error(name: str, message: str) -> ValueError:
    return ValueError(f"measurement.{name}: {message}")


def validate_measurement(m: MeasurementConfig) -> None:
    """Raise ``ValueError`` with a one-line message naming the first bad field."""
    def number(name: str) -> float:
        value = getattr(m, name)
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise _field_error(name, f"must be a number, got {value!r}")
        return float(value)

    rate = number("rate_hz")
    if not (math.isfinite(rate) and rate > 0.0):
        raise _field_error("rate_hz", f"must be > 0, got {m.rate_hz}")
    names = ("noise_std", "latency", "prior_window")
    optional = tuple(n for n in ("process_noise", "rot_noise_deg") if getattr(m, n) is not None)
    for name in names + optional:
        value = number(name)
        if not (math.isfinite(value) and value >= 0.0):
            raise _field_error(name, f"must be >= 0 and finite, got {getattr(m, name)}")
    _check_estimator(m)
    _check_sensor(m)
    if isinstance(m.seed, bool) or not isinstance(m.seed, int) or m.seed < 0:
        raise _field_error("seed", f"must be an integer >= 0, got {m.seed!r}")
    windows = []
    for i, window in enumerate(m.dropouts):
        where = f"dropouts[{i}]"
        if not isinstance(window, (list, tuple)) or len(window) != 2:
            raise _field_error(where, f"must be a [from, to] pair, got {window!r}")
        try:
            lo, hi = (float(v) for v in window)
        except (TypeError, ValueError):
            raise _field_error(where, f"must be two numbers, got {window!r}") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise _field_error(where, f"must be finite, got {list(window)}")
        if not lo < hi:
            raise _field_error(where, f"from must be < to, got [{lo}, {hi}]")
        windows.append((lo, hi, i))
    windows.sort()
    for (lo0, hi0, i0), (lo1, hi1, i1) in itertools.pairwise(windows):
        if lo1 < hi0:
            first, second = sorted((i0, i1))
            raise _field_error(f"dropouts[{second}]", f"overlaps dropouts[{first}] "
                               f"([{lo1}, {hi1}] and [{lo0}, {hi0}])")


def _check_sensor(m: MeasurementConfig) -> None:
    """``sensor`` and, for ``rgbd``, its camera (``perception.rgbd_camera.validate_camera``)."""
    if m.sensor not in SENSORS:
        raise _field_error("sensor", f"must be one of {', '.join(SENSORS)}, got {m.sensor!r}")
    if m.sensor == "pose":
        if m.camera is not None:
            raise _field_error("camera", "only with sensor: rgbd (the pose sensor is a formula, no image)")
        return
    if m.camera is None:
        raise _field_error("camera", "sensor: rgbd needs a camera (its pose: xyz + rpy_deg or "
                           "look_at + look_from)")
    if m.estimator == "none":
        raise _field_error("estimator", "sensor: rgbd needs an estimator (auto, kalman_cv or kalman_ca)")
    if not m.latency > TIME_TOL:
        raise _field_error("latency", "an rgbd camera needs a latency > 0 (its frame is processed after "
                           "it is taken; e.g. 0.033 at 30 Hz)")
    validate_camera(m.camera)


def _check_estimator(m: MeasurementConfig) -> None:
    """The estimator and the options that go with it (the retired ones name what to write)."""
    if m.estimator not in ESTIMATORS:
        raise _field_error("estimator", f"must be one of {', '.join(ESTIMATORS)}, got {m.estimator!r}")
    if m.estimator == "auto" and m.process_noise is not None:
        raise _field_error("process_noise", "estimator auto tunes itself: remove process_noise "
                           "(or choose estimator: kalman_cv / kalman_ca to set it by hand)")
    if m.estimator == "none":
        for name in ("noise_std", "latency", "rot_noise_deg"):
            if getattr(m, name) not in (0, None):
                raise _field_error(name, f"the noisy target without a camera is retired: remove "
                                   f"estimator: none to see the target through the camera "
                                   f"(estimator auto), or remove {name}")
        if m.dropouts:
            raise _field_error("dropouts", "the noisy target without a camera is retired: remove "
                               "estimator: none to see the target through the camera (estimator auto)")


def rotation_noise(m: MeasurementConfig) -> float:
    """σ_R (rad): the orientation samples' noise per axis (``rot_noise_deg`` or its default)."""
    return math.radians(DEFAULT_ROT_NOISE_DEG if m.rot_noise_deg is None else float(m.rot_noise_deg))


def process_noise(m: MeasurementConfig) -> float:
    """q of a hand-set filter: ``process_noise``, or DEFAULT_PROCESS_NOISE when not stated."""
    return DEFAULT_PROCESS_NOISE if m.process_noise is None else float(m.process_noise)


class _NoiseTable:
    """n_k for k = 0, 1, …: row k of one N(0, std²) stream from ``default_rng(seed)``.

    Rows are drawn in blocks as needed; sequential draws from one generator equal one
    large draw, so n_k depends on k only (not on when or how often it is asked for).
    """

    def __init__(self, std: float, seed):
        self._std = float(std)
        self._rng = np.random.default_rng(seed)
        self._rows = np.zeros((0, 3))

    def __call__(self, k: int) -> np.ndarray:
        if self._std == 0.0:
            return np.zeros(3)
        while k >= len(self._rows):
            self._rows = np.vstack([self._rows, self._rng.normal(0.0, self._std, (_NOISE_BLOCK, 3))])
        return self._rows[k]


class Camera(LeafSystem):
    """One object's camera (see the module docstring).

    Input port ``x_true`` (3): the object's true position.
    Output port ``measurement`` (5): [stamp, x, y, z, valid] of the newest visible sample.
    Discrete state (one group, W·N): N slots [stamp, x, y, z, valid] (W = 5), newest first,
    of the last N delivered samples (``valid`` = 0 marks an empty slot); its default
    value holds the newest pre-run samples when there is a ``history``.

    ``rotation=True`` (an object with an orientation) adds the input port ``R_true`` (9: its
    true orientation, row-major), the output port ``measured_rotation`` (11: [stamp, Z
    row-major, valid]) and Z to each slot (W = 14: [stamp, x, y, z, valid, Z]).

    ``history``: the object's true position as a function of time (a callable
    t → [x, y, z], or an object whose ``evaluate(t)`` starts with it, and whose
    ``rotation_values(t)`` starts with its orientation when it has one), used only
    for the pre-run samples t_k < 0 (``config.prior_window``).
    """

    def __init__(self, *, config: MeasurementConfig, seed_offset: int = 0, history=None,
                 rotation: bool = False):
        super().__init__()
        validate_measurement(config)
        self._config = config
        # a thrown object is seen from its release on (``visible_from`` of its history)
        self._visible_from = float(getattr(history, "visible_from", -math.inf))
        self._period = 1.0 / config.rate_hz
        self._latency = float(config.latency) if config.latency > TIME_TOL else 0.0
        self._windows = [(float(a), float(b)) for a, b in config.dropouts]
        seed = config.seed + seed_offset
        self._noise = _NoiseTable(config.noise_std, seed)
        self._rotation = bool(rotation)
        self._rot_noise = _NoiseTable(rotation_noise(config), [seed, 2]) if rotation else None
        self._width = 14 if rotation else 5
        self._slots = math.ceil(self._latency * config.rate_hz - TIME_TOL) + 2
        self._pre_run = self._take_pre_run(history, seed)

        self._x_in = self.DeclareVectorInputPort("x_true", 3)
        self._R_in = self.DeclareVectorInputPort("R_true", 9) if rotation else None
        buffer = np.zeros((self._slots, self._width))
        for slot, (t_k, z_k, Z_k) in zip(buffer, reversed(self._pre_run)):
            slot[:] = [t_k, *z_k, 1.0, *Z_k]
        self._buffer_index = self.DeclareDiscreteState(buffer.ravel())
        self.DeclarePeriodicDiscreteUpdateEvent(self._period, 0.0, self._take_sample)
        if self._latency > 0.0:
            # no-op: only makes the simulator stop where the output changes
            self.DeclarePeriodicPublishEvent(self._period, self._latency, lambda context: None)
            prerequisites = {self.time_ticket(), self.xd_ticket()}
        else:
            prerequisites = {self.time_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        self._measurement_out = self.DeclareVectorOutputPort(
            "measurement", 5, lambda c, o: o.SetFromVector(self._visible(c)[0:5]),
            prerequisites_of_calc=prerequisites)
        self._rotation_out = None if not rotation else self.DeclareVectorOutputPort(
            "measured_rotation", 11, lambda c, o: o.SetFromVector(self._visible_rotation(c)),
            prerequisites_of_calc=prerequisites)

    @property
    def config(self) -> MeasurementConfig:
        return self._config

    @property
    def buffer_slots(self) -> int:
        """N, the number of samples the delay buffer holds."""
        return self._slots

    @property
    def measures_rotation(self) -> bool:
        """Whether the camera also measures the object's orientation (``rotation``)."""
        return self._rotation

    def pre_run_samples(self, visible_by: float = 0.0) -> list:
        """[(t_k, z_k), …], oldest first: the delivered pre-run samples (t_k < 0) that are
        visible at ``visible_by`` (t_k + latency ≤ visible_by); empty without a history."""
        return [(t_k, z_k.copy()) for t_k, z_k, _ in self._pre_run
                if t_k + self._latency <= visible_by + TIME_TOL]

    def pre_run_rotations(self, visible_by: float = 0.0) -> list:
        """[(t_k, Z_k as 3×3), …] of the same pre-run samples (empty without ``rotation``)."""
        if not self._rotation:
            return []
        return [(t_k, np.reshape(Z_k, (3, 3)).copy()) for t_k, _, Z_k in self._pre_run
                if t_k + self._latency <= visible_by + TIME_TOL]

    def _take_pre_run(self, history, seed) -> list:
        """[(t_k, z_k, Z_k row-major or []), …] of the pre-run samples, oldest first."""
        window = float(self._config.prior_window)
        if history is None or window <= 0.0:
            return []
        position = history if callable(history) else (lambda t: history.evaluate(t)[0:3])
        turn = getattr(history, "rotation_values", lambda t: np.eye(3).ravel())
        noise = _NoiseTable(self._config.noise_std, [seed, 1])  # second stream: k < 0
        rot_noise = _NoiseTable(rotation_noise(self._config), [seed, 3]) if self._rotation else None
        count = math.floor(window * self._config.rate_hz + TIME_TOL)
        samples = []
        for j in range(count, 0, -1):  # k = −j, oldest first
            t_k = -j * self._period
            if not self.dropped(t_k):
                z = np.asarray(position(t_k), dtype=float)[0:3] + noise(j - 1)
                Z = [] if rot_noise is None else self._perturb(rot_noise(j - 1), turn(t_k)[0:9])
                samples.append((t_k, z, Z))
        return samples

    def get_x_true_input_port(self):
        return self._x_in

    def get_R_true_input_port(self):
        return self._R_in

    def get_measurement_output_port(self):
        return self._measurement_out

    def get_measured_rotation_output_port(self):
        return self._rotation_out

    def dropped(self, t: float) -> bool:
        """Whether a sample taken at t falls in a dropout window [from, to) or before the
        object can be seen (a thrown object before its release)."""
        if t < self._visible_from - TIME_TOL:
            return True
        return any(lo - TIME_TOL <= t < hi - TIME_TOL for lo, hi in self._windows)

    def sample(self, k: int, x_true: np.ndarray) -> np.ndarray:
        """z_k = x_true + n_k (3 values); n_k is fixed by k and the seed."""
        return np.asarray(x_true, dtype=float) + self._noise(k)

    def sample_rotation(self, k: int, R_true) -> list:
        """Z_k = exp([n_k^R]×) R_true (9 values, row-major); n_k^R is fixed by k and the seed."""
        return self._perturb(self._rot_noise(k), R_true)

    @staticmethod
    def _perturb(n, R_true) -> list:
        R = np.asarray(R_true, dtype=float).reshape(3, 3)
        return (rotation_from_vector(n).matrix() @ R).ravel().tolist()

    def _sample_index(self, t: float) -> int:
        return round(t * self._config.rate_hz)

    def _new_slot(self, context, t: float) -> np.ndarray:
        """[t, z_k, 1(, Z_k)] of the sample taken at t from the inputs."""
        k = self._sample_index(t)
        row = [t, *self.sample(k, self._x_in.Eval(context)), 1.0]
        if self._rotation:
            row += self.sample_rotation(k, self._R_in.Eval(context))
        return np.array(row)

    def _take_sample(self, context, discrete_state) -> None:
        t = context.get_time()
        if self.dropped(t):
            return
        buffer = discrete_state.get_mutable_vector(self._buffer_index)
        old = context.get_discrete_state(self._buffer_index).value()
        buffer.SetFromVector(np.concatenate([self._new_slot(context, t), old[:-self._width]]))

    def _visible(self, context) -> np.ndarray:
        """The slot (W values) of the newest sample visible at the context's time (zeros: none)."""
        t = context.get_time()
        slots = context.get_discrete_state(self._buffer_index).value().reshape(self._slots, self._width)
        if self._latency == 0.0:
            # the sample taken now is visible now, even before this instant's update stores it
            t_k = self._sample_index(t) * self._period
            newest = slots[0]
            stored = newest[4] > 0.5 and newest[0] >= t_k - TIME_TOL
            if abs(t - t_k) <= TIME_TOL and not stored and not self.dropped(t_k):
                return self._new_slot(context, t)
        for slot in slots:
            if slot[4] > 0.5 and slot[0] + self._latency <= t + TIME_TOL:
                return slot.copy()
        return np.zeros(self._width)

    def _visible_rotation(self, context) -> np.ndarray:
        """[stamp, Z row-major, valid] of the newest visible sample."""
        slot = self._visible(context)
        return np.concatenate([slot[0:1], slot[5:14], slot[4:5]])
