"""The interceptor closing the loop on what a camera sees (estimator mode, priming, scenarios)."""

import numpy as np
import pytest

from ptint_drake import cli
from ptint_drake.controllers.ptsmc.interceptor import PrescribedTimeInterceptor
from ptint_drake.simulation import build, simulate
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.systems.estimation.kalman import TargetKalmanFilter
from ptint_drake.systems.perception.camera import Camera, MeasurementConfig
from ptint_drake.systems.task.targets import LinearTarget, TargetSource
from ptint_drake.worlds.registry import objects_of

CAMERA_SCENARIOS = ("conveyor_pair_camera", "curve_camera", "conveyor_speedup_camera",
                    "conveyor_dropout_camera")


def test_estimator_mode_interceptor_has_no_target_object():
    built = build(load_scenario("conveyor_pair_camera"), log=False)
    systems = {s.get_name(): s for s in built.diagram.GetSystems()}
    interceptor = built.controller.system
    assert isinstance(interceptor, PrescribedTimeInterceptor)
    assert interceptor.has_target_input
    assert interceptor._targets is None  # holds no target object at all
    # no analytic TargetSource next to the controller (the station's true objects are inside
    # the station diagram, and reach the controller only through the cameras)
    assert not any(isinstance(s, TargetSource) for s in systems.values())
    links = built.diagram.connection_map()
    target_in = interceptor.GetInputPort("target")
    source, _ = links[(interceptor, target_in.get_index())]
    assert source.get_name() == "target_selector"
    for i in range(2):
        kf = systems[f"target_filter_{i}"]
        upstream, _ = links[(kf, kf.get_measurement_input_port().get_index())]
        assert upstream.get_name() == f"camera_{i}"
        camera = systems[f"camera_{i}"]
        upstream, _ = links[(camera, camera.get_x_true_input_port().get_index())]
        assert upstream.get_name() == "object_positions"


def test_filters_are_primed_at_t0_from_samples_seen_before_the_run():
    built = build(load_scenario("conveyor_pair_camera"), log=False)
    context = built.diagram.CreateDefaultContext()
    truths = objects_of(load_scenario("conveyor_pair_camera"))
    for i, truth in enumerate(truths):
        kf = built.diagram.GetSubsystemByName(f"target_filter_{i}")
        out = kf.get_target_output_port().Eval(kf.GetMyContextFromRoot(context))
        np.testing.assert_allclose(out[0:3], truth.evaluate(0.0)[0:3], atol=3e-3)
        np.testing.assert_allclose(out[3:6], truth.evaluate(0.0)[3:6], atol=1e-2)


def test_pre_run_samples_follow_the_camera_rules():
    target = LinearTarget([0.3, -0.1, 0.2], [0.0, 0.08, 0.0])
    config = MeasurementConfig(noise_std=0.002, rate_hz=30.0, latency=0.05, prior_window=0.5,
                               dropouts=[[-0.3, -0.2]], seed=4)
    camera = Camera(config=config, history=target)
    plain = Camera(config=config)
    samples = camera.pre_run_samples()
    stamps = np.array([t for t, _ in samples])
    assert np.all(stamps + 0.05 <= 1e-9) and np.all(stamps >= -0.5 - 1e-9)
    assert not np.any((stamps >= -0.3 - 1e-9) & (stamps < -0.2 - 1e-9))  # the dropout
    assert len(camera.pre_run_samples(visible_by=1.0)) == len(samples) + 1  # t_k = −1/30
    assert plain.pre_run_samples() == []
    # samples k >= 0 carry the same noise with or without a history
    np.testing.assert_array_equal(camera.sample(3, np.zeros(3)), plain.sample(3, np.zeros(3)))
    # the buffer at t = 0 shows the newest visible pre-run sample
    ctx = camera.CreateDefaultContext()
    camera.get_x_true_input_port().FixValue(ctx, np.zeros(3))
    z = camera.get_measurement_output_port().Eval(ctx)
    assert z[4] == 1.0 and z[0] == pytest.approx(samples[-1][0])
    # the filter's default state is what its update rule makes of those samples
    kf = TargetKalmanFilter(config=config, model="cv", prior=samples)
    meta, X, _ = kf.state(kf.CreateDefaultContext())
    assert meta[0] == 1.0 and meta[2] == pytest.approx(samples[-1][0])
    np.testing.assert_allclose(X[1], [0.0, 0.08, 0.0], atol=0.03)
    with pytest.raises(ValueError, match=r"^prior: "):
        TargetKalmanFilter(config=config, model="cv", prior=[(-0.01, np.zeros(3))])


@pytest.mark.parametrize("name", CAMERA_SCENARIOS)
def test_camera_scenarios_load_with_their_criteria(name):
    scenario = load_scenario(name)
    assert scenario.measurement.estimator == "auto" and scenario.measurement.process_noise is None
    assert scenario.measurement.rate_hz == 30.0 and scenario.measurement.noise_std == 0.002
    assert scenario.criteria.e_tf >= 0.003


@pytest.mark.parametrize("name, seeds, bound", [("conveyor_pair_camera", (1, 2, 3), 1.5e-3),
                                                ("conveyor_speedup_camera", (1, 2), 3e-3)])
def test_closed_loop_on_camera_samples(name, seeds, bound):
    e_tf, holds = [], []
    for seed in seeds:
        scenario = load_scenario(name)
        scenario.measurement.seed = seed
        metrics = simulate(scenario, check=False).metrics
        assert metrics["status"] == "ok", (seed, metrics["reasons"])
        for seg in metrics["segments"]:
            assert seg["e_half_norm"] >= 0.25 * seg["e0_norm"]  # not early
            e_tf.append(seg["e_tf_norm"])
            holds.append(seg["e_hold_max_norm"])
    assert np.median(e_tf) <= bound
    assert np.median(holds) <= 5e-3


@pytest.mark.parametrize("setting, field", [
    ("measurement.noise_std=-0.001", "measurement.noise_std"),
    ("measurement.estimator=kalman_xyz", "measurement.estimator"),
    ("measurement.prior_window=-1", "measurement.prior_window"),
    ("measurement.dropouts=[[0.5, 0.2]]", "measurement.dropouts[0]"),
])
def test_bad_measurement_value_is_one_line_exit_2(setting, field, capsys, tmp_path):
    code = cli.main(["run", "conveyor_pair_camera", "--set", setting, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert code == 2
    assert len(err.splitlines()) == 1 and err.startswith(f"ptint: error: --set: {field}:"), err
    assert not (tmp_path / "o").exists()


def test_bad_measurement_in_a_scenario_file(capsys, tmp_path):
    from ptint_drake.simulation.scenario import scenario_text

    _, text = scenario_text("conveyor_pair_camera")
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("rate_hz: 30.0", "rate_hz: 0.0"))
    assert cli.main(["run", str(bad), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("ptint: error: measurement.rate_hz:") and len(err.splitlines()) == 1
