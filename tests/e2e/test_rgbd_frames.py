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


def test_a_camera_pick_writes_its_estimates_figure_and_frames_at_the_first_fit_and_the_grasp(tmp_path):
    from ptint_drake.systems.perception.frame_images import GOOD
    from ptint_drake.worlds.pick.camera_frames import ESTIMATE, first_fit_time
    from ptint_drake.worlds.registry import world_of

    result = run_cached("conveyor_pick_place_rgbd")
    world = world_of(result.scenario)
    assert world.figure_files(result.scenario) == ["picks.png", "estimates.png"]
    tasks = world.view_tasks(result.scenario, result.series, result.metrics, tmp_path, True, False, False)
    assert [task[0] for task in tasks] == ["picks", "estimates", "camera_frames"]
    for task in tasks[1:]:
        world.draw_view(*task)
    assert (tmp_path / "estimates.png").stat().st_size > 10_000
    assert 0.0 <= first_fit_time(result.series, 0) < 0.2  # the part is in view from the start
    # the first frame's good fit and, in both, the estimate the pick aimed at (at the grasp the
    # fingers hide the part: no good fit there)
    for label, marks in (("pick0_first_fit", (GOOD, ESTIMATE)), ("pick0_grasp", (ESTIMATE,))):
        color = np.asarray(Image.open(tmp_path / "frames" / f"{label}_color.png"))[:, :, :3]
        for rgb in marks:
            assert np.count_nonzero(np.all(color == rgb, axis=-1)) >= 12, (label, rgb)
        assert (tmp_path / "frames" / f"{label}_depth.png").exists()
