"""The RGB-D perception (issue 34): part poses fitted to rendered depth images, from the image
and the configured geometry only."""

import math

import numpy as np
import pytest
from pydrake.common.value import AbstractValue
from pydrake.perception import BaseField, DepthImageToPointCloud
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.sensors import PixelType
from static_scene import StaticScene

from ptint_drake.config.measurement import BeltRegionConfig, MeasurementConfig, RgbdCameraConfig
from ptint_drake.systems.perception.camera import validate_measurement
from ptint_drake.systems.perception.part_fit import fit_parts
from ptint_drake.systems.perception.belt_regions import belt_regions, belts_under_paths
from ptint_drake.systems.perception.part_pose_estimator import (MakeRgbdPerception, PartPoseEstimator,
                                                                PerceptionConfig)
from ptint_drake.systems.perception.rgbd_camera import cloud_camera_info
from ptint_drake.systems.task.targets import LinearTarget

BELT = BeltRegionConfig(center=[0.3, 0.0, 0.1], direction=[0.0, 1.0, 0.0], length=0.4, width=0.08)
TILT = math.radians(30.0)  # from vertical, 0.5 m from the belt


def camera(noise: float = 0.0, **kw) -> RgbdCameraConfig:
    return RgbdCameraConfig(look_at=[0.3, 0.0, 0.1], look_from=[0.3 - 0.5 * math.sin(TILT), 0.0,
                                                                  0.1 + 0.5 * math.cos(TILT)],
                            depth_noise_scale=noise, **({"belts": [BELT]} | kw))


def good(fits):
    return [f for f in fits if f.ok]


def yaw_error_deg(fit_yaw: float, true_yaw: float, symmetry: float) -> float:
    d = (fit_yaw - true_yaw + 0.5 * symmetry) % symmetry - 0.5 * symmetry
    return abs(math.degrees(d))


@pytest.mark.parametrize("yaw_deg", [17.0, 90.0])
def test_box_fit_within_1mm_1deg_from_a_noiseless_render(yaw_deg):
    centre = np.array([0.305, 0.012, 0.115])  # 30 mm cube on the belt (top surface z = 0.1)
    fits, _ = StaticScene(camera(), [(centre, math.radians(yaw_deg))]).fits(0.0)
    (fit,) = good(fits)
    assert np.linalg.norm(fit.position - centre) < 1e-3
    assert fit.symmetry == pytest.approx(math.pi / 2)  # a cube: yaw known up to 90°
    assert yaw_error_deg(fit.yaw, math.radians(yaw_deg), fit.symmetry) < 1.0
    assert fit.inliers > 200 and fit.residual < 2e-3 and np.all(np.diag(fit.covariance) > 0)


@pytest.mark.parametrize("yaw_deg", [20.0, 45.0])
def test_a_noiseless_fit_has_no_half_pixel_bias(yaw_deg):
    """The cloud is back-projected where Drake renders (``rgbd_camera.RENDER_PIXEL_SHIFT``): with
    CameraInfo's own principal point this fit is ~0.7 mm off (half a pixel footprint)."""
    centre = np.array([0.305, 0.012, 0.115])
    (fit,) = good(StaticScene(camera(), [(centre, math.radians(yaw_deg))]).fits(0.0)[0])
    assert np.linalg.norm(fit.position - centre) < 0.15e-3


def test_box_fit_with_d415_noise_within_1mm_1deg():
    centre = np.array([0.29, -0.03, 0.115])
    scene = StaticScene(camera(noise=1.0), [(centre, math.radians(40.0))], seed=3)
    for t in (0.0, 1 / 30, 2 / 30):
        (fit,) = good(scene.fits(t)[0])
        assert np.linalg.norm(fit.position - centre) < 1e-3
        assert yaw_error_deg(fit.yaw, math.radians(40.0), fit.symmetry) < 1.0


def test_cylinder_centre_and_axis():
    c = camera(part_shape="cylinder", part_size=[0.04, 0.03])
    centre = np.array([0.31, 0.02, 0.115])
    (fit,) = good(StaticScene(c, [(centre, 0.7)]).fits(0.0)[0])
    assert np.linalg.norm(fit.position - centre) < 1e-3
    assert fit.symmetry == 0.0 and fit.yaw == 0.0  # any yaw
    assert math.degrees(math.acos(fit.axis[2])) < 1.0


def test_two_touching_boxes_on_one_belt_are_two_parts():
    a, b = np.array([0.30, -0.015, 0.115]), np.array([0.30, 0.015, 0.115])  # faces touching
    fits = good(StaticScene(camera(), [(a, 0.0), (b, 0.0)]).fits(0.0)[0])
    assert len(fits) == 2
    found = sorted(f.position[1] for f in fits)
    assert found == pytest.approx([a[1], b[1]], abs=1.5e-3)


def test_occluded_part_is_a_dropout():
    centre = np.array([0.30, 0.0, 0.115])
    # an arm link's worth of box 20 mm above the part, covering half of it from the camera
    occluder = ([0.05, 0.03, 0.02], [0.30, 0.015, 0.16])
    fits = StaticScene(camera(), [(centre, 0.0)], occluders=[occluder]).fits(0.0)[0]
    assert fits and not good(fits)
    assert all(f.reason for f in fits)


def test_something_above_a_part_makes_its_fit_a_dropout_when_checked():
    centre = np.array([0.30, 0.0, 0.115])
    # a 10 mm box 80 mm above the part, beyond it from the camera: the top face stays in view
    occluder = ([0.01, 0.01, 0.01], [0.33, 0.0, 0.21])
    seen = StaticScene(camera(), [(centre, 0.0)], occluders=[occluder]).fits(0.0)[0]
    checked = StaticScene(camera(), [(centre, 0.0)], occluders=[occluder], check_above=True).fits(0.0)[0]
    assert len(good(seen)) == 1
    assert checked and not good(checked) and "above it" in checked[0].reason


def test_a_calibration_error_moves_what_the_perception_sees():
    centre = np.array([0.30, 0.0, 0.115])
    (ok,) = good(StaticScene(camera(), [(centre, 0.0)]).fits(0.0)[0])
    shifted = camera(pose_error=[0.002, 0.0, 0.0, 0.0, 0.0, 0.0])
    (off,) = good(StaticScene(shifted, [(centre, 0.0)]).fits(0.0)[0])
    # the real camera 2 mm to its right: the part seen 2 mm to the left of where it is
    assert np.linalg.norm(off.position - ok.position) == pytest.approx(0.002, abs=5e-4)


def test_nothing_on_the_belt_gives_no_fit():
    assert StaticScene(camera(), []).fits(0.0)[0] == []


def test_perception_reads_only_the_depth_image():
    """The pipeline is built with the part poses disconnected: its one input is the image."""
    centre = np.array([0.295, -0.01, 0.115])
    scene = StaticScene(camera(), [(centre, 0.2)], perceive=False)
    depth = scene.camera.noise.get_output_port().Eval(scene.camera.noise.GetMyContextFromRoot(scene.context))
    config = PerceptionConfig(scene.camera.info, scene.camera.X_WC, belt_regions([BELT]), "box",
                              [0.03, 0.03, 0.03], [0], 30.0, 0.033)
    builder = DiagramBuilder()
    perception, _ = MakeRgbdPerception(config)
    builder.AddSystem(perception)
    diagram = builder.Build()
    assert perception.num_input_ports() == 1 and perception.get_input_port(0).get_name() == "depth_image"
    context = diagram.CreateDefaultContext()
    perception.get_input_port(0).FixValue(perception.GetMyMutableContextFromRoot(context), depth)
    simulator = Simulator(diagram, context)
    port = perception.GetOutputPort("measurement_0")
    assert port.Eval(perception.GetMyContextFromRoot(context))[4] == 0.0  # nothing seen yet
    simulator.AdvanceTo(0.034)  # frame 0 taken at t = 0, visible at 0.033
    z = port.Eval(perception.GetMyContextFromRoot(context))
    assert z[0] == 0.0 and z[4] == 1.0
    assert np.linalg.norm(z[1:4] - centre) < 1e-3
    quality = perception.GetOutputPort("quality_0").Eval(perception.GetMyContextFromRoot(context))
    assert quality[0] == 0.0 and quality[6] == 1.0 and quality[1] > 200 and 0.0 < quality[2] < 2e-3
    assert np.all(quality[3:6] > 0.0) and np.all(np.sqrt(quality[3:6]) < 1e-3)


def test_rgbd_measurement_fields_are_checked():
    validate_measurement(MeasurementConfig(sensor="rgbd", latency=0.033, camera=camera()))
    cases = [(MeasurementConfig(sensor="depth"), "measurement.sensor"),
             (MeasurementConfig(sensor="rgbd", latency=0.033), "measurement.camera"),
             (MeasurementConfig(sensor="rgbd", camera=camera()), "measurement.latency"),
             (MeasurementConfig(camera=camera()), "measurement.camera"),
             (MeasurementConfig(sensor="rgbd", latency=0.033, camera=RgbdCameraConfig()),
              "measurement.camera.xyz"),
             (MeasurementConfig(sensor="rgbd", latency=0.033, camera=camera(fov_y_deg=0.0)),
              "measurement.camera.fov_y_deg")]
    for config, field in cases:
        with pytest.raises(ValueError, match=field.replace(".", r"\.")):
            validate_measurement(config)


def test_derived_belts_of_parallel_paths_keep_their_own_parts():
    """conveyor_yaw's first and third objects ride parallel paths 50 mm apart at one height: the
    belts derived under them must each see only their own part."""

    targets = [LinearTarget([0.30, -0.05, 0.115], [0.0, 0.1, 0.0]), LinearTarget([0.25, -0.05, 0.115],
                                                                                 [0.0, 0.1, 0.0])]
    belts, of = belts_under_paths(targets, 1.0, "box", [0.03, 0.03, 0.03])
    assert of == [0, 1]
    c = camera()
    scene = StaticScene(c, [(np.array([0.30, 0.0, 0.115]), 0.0), (np.array([0.25, 0.02, 0.115]), 0.0)],
                        perceive=False)
    estimator = PartPoseEstimator(PerceptionConfig(scene.camera.info, scene.camera.X_WC, belts, "box",
                                                   [0.03] * 3, of, 30.0, 0.033))
    builder = DiagramBuilder()
    to_cloud = builder.AddSystem(DepthImageToPointCloud(cloud_camera_info(scene.camera.info),
                                                        PixelType.kDepth32F, 1.0, BaseField.kXYZs))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    depth = scene.camera.noise.get_output_port().Eval(scene.camera.noise.GetMyContextFromRoot(scene.context))
    to_cloud.depth_image_input_port().FixValue(to_cloud.GetMyMutableContextFromRoot(context), depth)
    to_cloud.camera_pose_input_port().FixValue(to_cloud.GetMyMutableContextFromRoot(context),
                                               AbstractValue.Make(scene.camera.X_WC))
    cloud = to_cloud.point_cloud_output_port().Eval(to_cloud.GetMyContextFromRoot(context))
    fits = good(fit_parts(estimator.frame_points(cloud), belts, "box", [0.03] * 3))
    assert sorted((f.belt, round(f.position[0], 2)) for f in fits) == [(0, 0.30), (1, 0.25)]


def test_depth_noise_grows_with_depth_squared_and_drops_grazing_pixels():
    from pydrake.systems.sensors import CameraInfo

    from ptint_drake.systems.perception.depth_noise import NOISE_PER_Z2, noisy_depth

    info = CameraInfo(320, 240, math.radians(45.0))
    for z in (0.5, 1.0):
        flat = np.full((240, 320), z, np.float32)  # a wall facing the camera
        noisy = noisy_depth(flat, info, np.random.default_rng(1))
        inner = noisy[20:-20, 20:-20]
        assert np.std(inner - z) == pytest.approx(NOISE_PER_Z2 * z * z, rel=0.05)
        assert np.mean(inner == 0.0) < 0.01
    # a surface seen at ~80° incidence (depth × (1 + tan 80° / f) per row; steps < the 10 mm of
    # an edge): missing with probability ~(80 - 65) / 20
    rows = (1.0 + math.tan(math.radians(80.0)) / info.focal_y()) ** np.arange(24, dtype=np.float64)
    grazing = np.full((240, 320), np.inf, np.float32)
    grazing[0:24] = 0.3 * rows[:, None]
    noisy = noisy_depth(grazing, info, np.random.default_rng(2))
    assert 0.5 < np.mean(noisy[2:22, 20:-20] == 0.0) < 0.95
    assert np.array_equal(noisy_depth(flat, info, np.random.default_rng(1), scale=0.0), flat)


@pytest.mark.parametrize("yaw_deg", [0.0, 20.0, 45.0])
def test_parts_overhanging_their_belts_toward_each_other_are_fitted_once_on_their_own_belts(yaw_deg):
    """30 mm cubes 13 mm off the centre lines of two 40 mm belts 50 mm apart, toward each other: at
    45° their corners are 34 mm from their lines, 14 mm over their belts' edges and into the
    other belt's band.  The crop keeps each belt's band widened by the part's half-diagonal, so
    the top faces stay whole (cut at the belt's edge, the cube at 0° was 22 mm wide: not seen);
    each part is fitted once, on the belt under its centre."""
    a = BeltRegionConfig(center=[0.3, 0.0, 0.1], direction=[0.0, 1.0, 0.0], length=0.4, width=0.04)
    b = BeltRegionConfig(center=[0.35, 0.0, 0.1], direction=[0.0, 1.0, 0.0], length=0.4, width=0.04)
    parts = [(np.array([0.313, 0.0, 0.115]), math.radians(yaw_deg)),  # on a, 13 mm toward b
             (np.array([0.337, 0.06, 0.115]), math.radians(yaw_deg + 10.0))]  # on b, 13 mm toward a
    fits = StaticScene(camera(belts=[a, b]), parts, object_belts=[0, 1]).fits(0.0)[0]
    assert len(fits) == 2 and all(f.ok for f in fits), [(f.belt, f.reason) for f in fits]
    for belt, (centre, yaw) in enumerate(parts):
        (fit,) = [f for f in fits if f.belt == belt]
        assert np.linalg.norm(fit.position - centre) < 1e-3
        assert yaw_error_deg(fit.yaw, yaw, fit.symmetry) < 1.0
