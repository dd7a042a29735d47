"""The frames a ``measurement.sensor: rgbd`` run writes (issue 34, "seeing what the camera sees")."""

import numpy as np
from conftest import run_cached
from PIL import Image

from ptint_drake.worlds.interception.camera_frames import write_camera_frames


def test_frames_show_the_belts_and_a_good_fit_at_every_instant(tmp_path):
    result = run_cached("conveyor_pair_rgbd")
    names = write_camera_frames(result.scenario, result.series, tmp_path)
    camera = result.scenario.measurement.camera
    segments = len(result.scenario.interceptions)
    assert len(names) == 2 * 3 * segments  # colour + depth at start, half-way and tf of each segment
    for name in names:
        image = np.asarray(Image.open(tmp_path / name))
        assert image.shape[:2] == (camera.height, camera.width), name
        if name.endswith("_depth.png"):
            # belts, parts and arm (~20 % of the frame; the sky beyond them has no depth)
            seen = np.count_nonzero(image) / image.size
            assert seen > 0.1, f"{name}: only {seen:.0%} of the depth pixels are valid"
        else:
            # a good fit is drawn as a pure green cross: (40, 220, 40)
            green = np.all(image[:, :, :3] == (40, 220, 40), axis=-1)
            assert np.count_nonzero(green) >= 12, f"{name}: no fit mark drawn"
