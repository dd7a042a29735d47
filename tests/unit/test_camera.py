"""The camera: sample times, hold, delay, noise and dropouts (systems/perception/camera.py)."""

import numpy as np
import pytest
from pydrake.common.yaml import yaml_load_typed
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from ptint_drake.systems.perception.camera import Camera, MeasurementConfig, validate_measurement

VELOCITY = np.array([1.0, -2.0, 0.5])


def _line_source(builder, duration=5.0):
    """x_true(t) = VELOCITY t, as a TrajectorySource (time-dependent, no state)."""
    traj = PiecewisePolynomial.FirstOrderHold(
        [0.0, duration], np.column_stack([np.zeros(3), VELOCITY * duration]))
    return builder.AddSystem(TrajectorySource(traj))


class _Recorder(LeafSystem):
    """Reads ``measurement`` in a periodic *discrete update* (as a filter would) and logs it."""

    def __init__(self, period, offset):
        super().__init__()
        self.log = []
        self._in = self.DeclareVectorInputPort("measurement", 5)
        self.DeclareDiscreteState(1)
        self.DeclarePeriodicDiscreteUpdateEvent(period, offset, self._read)

    def _read(self, context, discrete_state):
        self.log.append((context.get_time(), self._in.Eval(context).copy()))


def _camera_diagram(config, recorder_offset=None, source=None):
    builder = DiagramBuilder()
    src = source(builder) if source else _line_source(builder)
    camera = builder.AddSystem(Camera(config=config))
    builder.Connect(src.get_output_port(), camera.get_x_true_input_port())
    recorder = None
    if recorder_offset is not None:
        recorder = builder.AddSystem(_Recorder(1.0 / config.rate_hz, recorder_offset))
        builder.Connect(camera.get_measurement_output_port(), recorder.get_input_port())
    diagram = builder.Build()
    return diagram, camera, recorder


@pytest.mark.parametrize("rate, latency", [(10.0, 0.0), (10.0, 0.05), (10.0, 0.1), (30.0, 0.1),
                                           (30.0, 0.25), (7.0, 1.0 / 7.0)])
def test_downstream_update_at_stamp_plus_latency_sees_that_sample(rate, latency):
    """A discrete update at t_k + L reads sample k: stamp t_k, value x_true(t_k)
    (latency 0, latency a multiple of the period, 0.1·30 = 3.0000000000000004, …)."""
    config = MeasurementConfig(rate_hz=rate, latency=latency)
    diagram, _, recorder = _camera_diagram(config, recorder_offset=latency)
    Simulator(diagram).AdvanceTo(2.0)
    assert len(recorder.log) >= int((2.0 - latency) * rate) - 1  # updates at 2.0 itself come later
    for k, (t, m) in enumerate(recorder.log):
        assert t == pytest.approx(k / rate + latency, abs=1e-12)
        assert m[4] == 1.0
        assert m[0] == pytest.approx(k / rate, abs=1e-12)
        np.testing.assert_allclose(m[1:4], VELOCITY * m[0], atol=1e-12)


def test_output_is_a_held_delayed_sample():
    """Between visibility times the output holds; before the first one it is invalid."""
    rate, latency = 10.0, 0.05
    diagram, camera, _ = _camera_diagram(MeasurementConfig(rate_hz=rate, latency=latency))
    sim = Simulator(diagram)
    port = camera.get_measurement_output_port()
    ctx = camera.GetMyContextFromRoot(sim.get_mutable_context())
    for t in np.arange(0.0, 1.0, 0.0125):
        sim.AdvanceTo(t)
        m = port.Eval(ctx)
        if t < latency - 1e-9:
            np.testing.assert_array_equal(m, np.zeros(5))
            continue
        k = np.floor((t - latency) * rate + 1e-9)
        assert m[0] == pytest.approx(k / rate, abs=1e-12), t
        np.testing.assert_allclose(m[1:4], VELOCITY * k / rate, atol=1e-12)
        assert m[4] == 1.0


def test_buffer_is_discrete_state():
    camera = Camera(config=MeasurementConfig(rate_hz=30.0, latency=0.1))
    ctx = camera.CreateDefaultContext()
    assert camera.buffer_slots == 5  # ⌈0.1·30⌉ + 2
    assert ctx.get_discrete_state_vector().size() == 5 * camera.buffer_slots
    assert camera.get_measurement_output_port().Eval(ctx)[4] == 0.0


def test_noise_statistics_and_seed():
    std = 0.01
    cam = Camera(config=MeasurementConfig(noise_std=std, seed=4))
    z = np.array([cam.sample(k, np.zeros(3)) for k in range(6000)])
    n = z.size
    assert abs(z.mean()) < 4 * std / np.sqrt(n)
    assert z.std() == pytest.approx(std, rel=0.03)
    assert abs(np.corrcoef(z[:-1, 0], z[1:, 0])[0, 1]) < 0.05  # white in time
    assert abs(np.corrcoef(z[:, 0], z[:, 1])[0, 1]) < 0.05  # independent axes
    same = Camera(config=MeasurementConfig(noise_std=std, seed=4))
    np.testing.assert_array_equal(same.sample(5999, np.zeros(3)), z[5999])  # asked out of order
    np.testing.assert_array_equal(same.sample(3, np.zeros(3)), z[3])
    other = Camera(config=MeasurementConfig(noise_std=std, seed=4), seed_offset=1)
    assert not np.allclose(other.sample(3, np.zeros(3)), z[3])
    np.testing.assert_array_equal(Camera(config=MeasurementConfig(noise_std=std, seed=5)).sample(
        3, np.zeros(3)), other.sample(3, np.zeros(3)))


def _simulated_samples(config, extra_evaluations):
    diagram, camera, recorder = _camera_diagram(config, recorder_offset=config.latency)
    sim = Simulator(diagram)
    if extra_evaluations:  # evaluate the output many times in between: must not change anything
        ctx = camera.GetMyContextFromRoot(sim.get_mutable_context())
        for t in np.linspace(0.0, 1.0, 97):
            sim.AdvanceTo(t)
            for _ in range(3):
                camera.get_measurement_output_port().Eval(ctx)
    sim.AdvanceTo(1.0)
    return np.array([m for _, m in recorder.log])


def test_simulated_noise_is_reproducible_and_independent_of_evaluations():
    config = MeasurementConfig(noise_std=0.002, rate_hz=20.0, latency=0.03, seed=7)
    a = _simulated_samples(config, False)
    b = _simulated_samples(config, True)
    np.testing.assert_array_equal(a, b)
    cam = Camera(config=config)
    for m in a:
        k = round(m[0] * 20.0)
        np.testing.assert_array_equal(m[1:4], cam.sample(k, VELOCITY * m[0]))
    assert np.std(a[:, 1:4] - VELOCITY * a[:, :1]) > 0.001


def test_dropouts_deliver_no_new_sample():
    config = MeasurementConfig(rate_hz=10.0, latency=0.05, dropouts=[[0.25, 0.45], [0.8, 0.9]])
    diagram, _, recorder = _camera_diagram(config, recorder_offset=0.05)
    Simulator(diagram).AdvanceTo(1.26)  # events at the end time run on the next step
    stamps = [round(m[0], 9) for _, m in recorder.log]
    #          reads at t_k + 0.05 for t_k = 0, 0.1, …, 1.2
    assert stamps == [0.0, 0.1, 0.2, 0.2, 0.2, 0.5, 0.6, 0.7, 0.7, 0.9, 1.0, 1.1, 1.2]
    assert all(m[4] == 1.0 for _, m in recorder.log)


def test_dropout_at_start_means_no_valid_sample_yet():
    config = MeasurementConfig(rate_hz=10.0, dropouts=[[0.0, 0.3]])
    diagram, _, recorder = _camera_diagram(config, recorder_offset=0.0)
    Simulator(diagram).AdvanceTo(0.55)
    valid = [m[4] for _, m in recorder.log]
    assert valid == [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]


def test_constant_input_with_fixed_value():
    """FixValue on x_true and a context advanced by hand: the latency-0 output is live."""
    camera = Camera(config=MeasurementConfig(rate_hz=10.0))
    ctx = camera.CreateDefaultContext()
    camera.get_x_true_input_port().FixValue(ctx, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(camera.get_measurement_output_port().Eval(ctx), [0, 1, 2, 3, 1])
    ctx.SetTime(0.05)  # between samples, nothing stored yet: nothing visible
    assert camera.get_measurement_output_port().Eval(ctx)[4] == 0.0


def test_constant_source_diagram_runs_long():
    builder = DiagramBuilder()
    src = builder.AddSystem(ConstantVectorSource([0.1, 0.2, 0.3]))
    camera = builder.AddSystem(Camera(config=MeasurementConfig(rate_hz=100.0, latency=0.013)))
    builder.Connect(src.get_output_port(), camera.get_x_true_input_port())
    diagram = builder.Build()
    sim = Simulator(diagram)
    sim.AdvanceTo(100.0)
    m = camera.get_measurement_output_port().Eval(camera.GetMyContextFromRoot(sim.get_context()))
    assert m[0] == pytest.approx(99.98, abs=1e-9)  # round-off at t = 100 s stays inside TIME_TOL
    np.testing.assert_allclose(m[1:], [0.1, 0.2, 0.3, 1.0])


def test_yaml_loads_config():
    m = yaml_load_typed(schema=MeasurementConfig, data=(
        "{noise_std: 0.001, rate_hz: 60, latency: 0.02, compensate_latency: true, "
        "dropouts: [[1.0, 1.5]], seed: 3, estimator: kalman_ca, process_noise: 0.5}"))
    assert m == MeasurementConfig(0.001, 60.0, 0.02, True, [[1.0, 1.5]], 3, "kalman_ca", 0.5)
    validate_measurement(m)


@pytest.mark.parametrize("changes, field", [
    ({"rate_hz": 0.0}, "rate_hz"),
    ({"rate_hz": float("nan")}, "rate_hz"),
    ({"noise_std": -1e-3}, "noise_std"),
    ({"noise_std": float("nan")}, "noise_std"),
    ({"latency": -0.1}, "latency"),
    ({"process_noise": -1.0, "estimator": "kalman_cv"}, "process_noise"),
    ({"process_noise": float("inf"), "estimator": "kalman_cv"}, "process_noise"),
    ({"estimator": "ekf"}, "estimator"),
    ({"seed": -1}, "seed"),
    ({"dropouts": [[0.5, 0.2]]}, "dropouts[0]"),
    ({"dropouts": [[0.5, 0.5]]}, "dropouts[0]"),
    ({"dropouts": [[0.1, 0.2], [0.3]]}, "dropouts[1]"),
    ({"dropouts": [[0.1, 0.2, 0.3]]}, "dropouts[0]"),
    ({"dropouts": [[0.1, 0.5], [0.4, 0.6]]}, "dropouts[1]"),
    ({"dropouts": [[1.0, 2.0], [0.1, 0.5], [1.5, 3.0]]}, "dropouts[2]"),
])
def test_validation_names_the_field(changes, field):
    config = MeasurementConfig(**changes)
    with pytest.raises(ValueError) as info:
        validate_measurement(config)
    message = str(info.value)
    assert message.startswith(f"measurement.{field}: "), message
    assert "\n" not in message
    with pytest.raises(ValueError):
        Camera(config=config)


def test_validation_accepts_touching_windows_and_message_example():
    validate_measurement(MeasurementConfig(dropouts=[[0.2, 0.3], [0.1, 0.2]]))
    with pytest.raises(ValueError, match=r"^measurement\.rate_hz: must be > 0, got 0$"):
        validate_measurement(MeasurementConfig(rate_hz=0))
