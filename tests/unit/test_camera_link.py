"""The depth camera over the link (``hardware.camera_link``): Drake's own image message, read back
bit for bit, and what Drake's ``ApplyCameraConfig`` publishes read by the same function."""

from __future__ import annotations

import numpy as np
from pydrake.lcm import DrakeLcm
from pydrake.multibody.plant import AddMultibodyPlant, MultibodyPlantConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.lcm import LcmBuses
from pydrake.systems.sensors import ApplyCameraConfig, CameraConfig, ImageDepth32F

from ptint_drake.hardware.camera_link import frame_due, image_channel, pack_depth_image, unpack_depth_image


def test_a_depth_image_round_trips_bit_for_bit():
    image = ImageDepth32F(5, 3)
    rng = np.random.default_rng(0)
    image.mutable_data[:] = rng.uniform(0.1, 2.0, (3, 5, 1)).astype(np.float32)
    image.mutable_data[1, 2, 0] = np.inf  # a pixel that saw nothing
    utime, back = unpack_depth_image(pack_depth_image(0.0123, image, "camera"))
    assert utime == 12300 and back.width() == 5 and back.height() == 3
    assert np.array_equal(np.asarray(back.data), np.asarray(image.data))


def test_frames_fall_in_exactly_one_tick():
    """30 Hz frames on a 1 ms grid: each frame with the status of the tick whose state it shows,
    the one period (t, t + T] that holds it; the frame at 0 with the hand-shake."""
    ticks = [k * 1e-3 for k in range(1000)]
    due = [t for t in ticks if frame_due(t, 1e-3, 30.0)]
    assert len(due) == 30 and abs(due[0] - 0.033) < 1e-12 and abs(due[2] - 0.099) < 1e-12  # 0.1: on a tick
    assert frame_due(0.0, 1e-3, 30.0, handshake=True) and not frame_due(0.0, 1e-3, 30.0)
    assert not frame_due(0.001, 1e-3, 30.0, handshake=True)


def test_reads_what_drakes_camera_publishes():
    """A camera applied by Drake's ``ApplyCameraConfig`` (hardware_sim's way) publishes on
    ``DRAKE_RGBD_CAMERA_IMAGES_<name>``; ``unpack_depth_image`` reads its depth image."""
    builder = DiagramBuilder()
    AddMultibodyPlant(MultibodyPlantConfig(time_step=0.001), builder)[0].Finalize()
    lcm = DrakeLcm("memq://")
    buses = LcmBuses()
    buses.Add("default", lcm)
    config = CameraConfig(name="camera", width=32, height=24, rgb=False, depth=True, fps=10.0)
    ApplyCameraConfig(config=config, builder=builder, lcm_buses=buses)
    got = []
    lcm.Subscribe(image_channel("camera"), got.append)
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    diagram.ForcedPublish(context)
    lcm.HandleSubscriptions(0)
    assert got, "Drake's camera published nothing"
    utime, image = unpack_depth_image(bytes(got[-1]))
    assert utime == 0 and (image.width(), image.height()) == (32, 24)
    assert np.all(np.isinf(np.asarray(image.data)))  # an empty scene: nothing in range (16U: 65535)
