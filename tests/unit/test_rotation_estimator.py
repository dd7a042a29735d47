"""Orientation from the camera (issue 21): the camera's orientation samples, the SO(3) filter of
systems/estimation/rotation_estimator.py, its wiring to the interceptor's ``target_rotation`` and the
scenario field ``measurement.rot_noise_deg``."""

import math

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.simulation import build
from ptint_drake.simulation.scenario import ScenarioError, load_scenario, parse_with_overrides, scenario_text
from ptint_drake.systems.estimation.rotation_estimator import RotationEstimator
from ptint_drake.systems.perception.camera import Camera, MeasurementConfig
from ptint_drake.systems.task.orientation import (ObjectRotations, OrientedTarget, SpinningOrientation,
                                                  rotation_angle, rotation_log)
from ptint_drake.systems.task.targets import LinearTarget

LINE = LinearTarget([0.3, 0.0, 0.15], [0.0, 0.1, 0.0])


def _loop(target, config, until: float, reads=()):
    """True orientation → camera → estimator, simulated to ``until``; returns (estimator, its
    context, {t: (output, P)} at each time of ``reads``)."""
    builder = DiagramBuilder()
    truth = builder.AddSystem(ObjectRotations([target]))
    still = builder.AddSystem(ConstantVectorSource(np.zeros(3)))
    camera = builder.AddSystem(Camera(config=config, history=target, rotation=True))
    estimator = builder.AddSystem(RotationEstimator(config=config, prior=camera.pre_run_rotations()))
    builder.Connect(truth.get_output_port(), camera.get_R_true_input_port())
    builder.Connect(still.get_output_port(), camera.get_x_true_input_port())
    builder.Connect(camera.get_measured_rotation_output_port(), estimator.get_measured_rotation_input_port())
    simulator = Simulator(builder.Build())
    context = estimator.GetMyContextFromRoot(simulator.get_mutable_context())
    read = {}
    for t in sorted(reads) + [until]:
        simulator.AdvanceTo(t)
        read[t] = (estimator.get_target_rotation_output_port().Eval(context).copy(),
                   estimator.state(context)[3])
    return estimator, context, read


@pytest.mark.parametrize("rate_deg_s", [(0.0, 0.0, 0.0), (0.0, -20.0, 30.0)])
def test_noiseless_constant_and_constant_rate_rotation_converge(rate_deg_s):
    """A part at rest (conveyor_yaw) and a frame turning at a constant rate (curve_pose's),
    seen without noise at 30 Hz, 33 ms late: R, ω at t (between updates) to ≤ 1e-6."""
    target = OrientedTarget(LINE, SpinningOrientation([150.0, 50.0, 180.0], rate_deg_s))
    config = MeasurementConfig(latency=0.033, rot_noise_deg=0.0)
    t_end = 2.0 + 0.4 / 30.0  # between two updates: the output is a prediction
    _, _, read = _loop(target, config, t_end)
    out = read[t_end][0]
    truth = target.rotation_values(t_end)
    assert rotation_angle(out[0:9].reshape(3, 3), np.reshape(truth[0:9], (3, 3))) <= 1e-6
    np.testing.assert_allclose(out[9:12], np.radians(rate_deg_s), atol=1e-6)
    np.testing.assert_array_equal(out[12:15], 0.0)


def test_covariance_stays_symmetric_positive_definite_through_a_dropout():
    target = OrientedTarget(LINE, SpinningOrientation([0.0, 0.0, 30.0], [0.0, 0.0, 20.0]))
    config = MeasurementConfig(latency=0.033, rot_noise_deg=1.0, dropouts=[[1.0, 1.5]], seed=3)
    reads = (0.9, 1.2, 1.45, 1.6, 2.0)
    _, _, read = _loop(target, config, 2.5, reads)
    variances = []
    for t in reads:
        P = read[t][1]
        np.testing.assert_array_equal(P, P.T)
        assert np.linalg.eigvalsh(P).min() > 0.0
        variances.append(P[0, 0])
    assert variances[1] < variances[2]  # grows while nothing is seen
    assert variances[3] < variances[2] and variances[4] < variances[2]  # shrinks once samples return
    out = read[2.5][0]  # and it is back on the object: well within 3 σ_R of the truth
    assert math.degrees(rotation_angle(out[0:9].reshape(3, 3),
                                       np.reshape(target.rotation_values(2.5)[0:9], (3, 3)))) < 1.5


def test_rotation_samples_leave_the_position_samples_alone_and_have_the_stated_noise():
    config = MeasurementConfig(noise_std=0.002, seed=7, rot_noise_deg=2.0)
    plain, turning = Camera(config=config), Camera(config=config, rotation=True)
    R = SpinningOrientation([10.0, -20.0, 30.0]).R0
    for k in (0, 1, 500):
        np.testing.assert_array_equal(plain.sample(k, np.zeros(3)), turning.sample(k, np.zeros(3)))
    n = np.array([rotation_log(np.reshape(turning.sample_rotation(k, R), (3, 3)) @ R.T) for k in range(3000)])
    np.testing.assert_allclose(np.degrees(n.std(axis=0)), 2.0, rtol=0.06)
    assert np.abs(np.degrees(n.mean(axis=0))).max() < 0.15


def test_camera_scenario_feeds_the_estimate_to_target_rotation():
    """conveyor_yaw_camera: the interceptor's ``target_rotation`` comes from the rotation
    selector of the camera's filters (fused and blocks), never from the analytic orientation."""
    for implementation in ("fused", "blocks"):
        scenario = load_scenario("conveyor_yaw_camera")
        scenario.controller.implementation = implementation
        built = build(scenario, log=False)
        names = {s.get_name() for s in built.diagram.GetSystems()}
        assert {"rotation_filter_0", "rotation_filter_1", "rotation_filter_2", "rotation_selector"} <= names
        assert "target_rotation_view" not in names
        rotation_in = built.controller.system
        if implementation == "blocks":
            rotation_in = next(s for s in built.diagram.GetSystems() if s.get_name() == "interceptor_surface")
        source, _ = built.diagram.connection_map()[(rotation_in, rotation_in.GetInputPort("target_rotation")
                                                    .get_index())]
        assert source.get_name() == "rotation_selector"


@pytest.mark.parametrize("override, message", [
    ("measurement.rot_noise_deg=-1", "measurement.rot_noise_deg: must be >= 0"),
    ("measurement.rot_noise_deg=.nan", "measurement.rot_noise_deg: must be >= 0"),
    ("measurement.rot_noise_deg=one", "measurement.rot_noise_deg: expected a number"),
])
def test_rot_noise_deg_bad_values_name_the_field(override, message):
    _, text = scenario_text("conveyor_yaw_camera")
    with pytest.raises(ScenarioError, match=f"^(--set: )?{message}") as info:
        parse_with_overrides(text, [override])
    assert "\n" not in str(info.value)


def test_rot_noise_deg_needs_a_target_with_an_orientation_and_a_camera():
    _, text = scenario_text("conveyor_pair_camera")
    with pytest.raises(ScenarioError, match="measurement.rot_noise_deg: no target has an orientation"):
        parse_with_overrides(text, ["measurement.rot_noise_deg=1.0"])
    _, text = scenario_text("conveyor_yaw_camera")
    with pytest.raises(ScenarioError, match="measurement.rot_noise_deg: the noisy target without a camera"):
        parse_with_overrides(text, ["measurement.estimator=none", "measurement.noise_std=0",
                                    "measurement.latency=0"])
    assert parse_with_overrides(text, ["measurement.rot_noise_deg=0"]).measurement.rot_noise_deg == 0


ROTATION_PLUGIN = '''
import numpy as np
from pydrake.systems.framework import LeafSystem


class RotationReader(LeafSystem):
    def __init__(self, plant, end_effector, params):
        super().__init__()
        self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorInputPort("target", 9)
        self.DeclareVectorInputPort("target_rotation", 15)
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(),
                                     lambda context, out: out.SetFromVector(np.zeros(out.size())))
'''

PLUGIN_ON_CAMERA = """duration: 1.0
robot: {model: rvm1_5dof, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0, 0.0, 0.0]}
controller: {type: "rotation_reader:RotationReader", task: top_down}
interceptions:
  - {start: 0.0, tf: 0.5, beta: 0.75,
     target: {linear: {start: [0.20, -0.23, 0.25], velocity: [0.0, 0.1, 0.0]},
              orientation: {rpy_deg: [0.0, 0.0, 30.0]}}}
measurement: {rate_hz: 30.0, noise_std: 0.002, latency: 0.033}
"""


def test_a_plugin_declaring_target_rotation_gets_the_cameras_estimate(tmp_path, monkeypatch):
    from ptint_drake.simulation.scenario import parse_scenario  # noqa: PLC0415

    (tmp_path / "rotation_reader.py").write_text(ROTATION_PLUGIN)
    monkeypatch.syspath_prepend(str(tmp_path))
    built = build(parse_scenario(PLUGIN_ON_CAMERA), log=False)
    system = built.controller.system
    port = system.GetInputPort("target_rotation")
    source, _ = built.diagram.connection_map()[(system, port.get_index())]
    assert source.get_name() == "rotation_selector"
    R = port.Eval(system.GetMyContextFromRoot(built.diagram.CreateDefaultContext()))[0:9]
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    # primed by the camera's second in view before t = 0 (default rot_noise_deg 1°): near Rz(30°)
    angle = math.degrees(rotation_angle(R.reshape(3, 3), np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])))
    assert 0.0 < angle < 1.0
