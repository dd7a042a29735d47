"""The frames a ``measurement.sensor: rgbd`` run writes (issue 34, "seeing what the camera sees")."""

import numpy as np
import pytest
from conftest import run_cached
from PIL import Image

from ptint_drake.worlds.interception.camera_frames import write_camera_frames


@pytest.mark.both_ends
def test_frames_show_the_belts_and_a_good_fit_at_every_instant(tmp_path):
    result = run_cached("conveyor_pair_rgbd")
    names = write_camera_frames(result.scenario, result.series, tmp_path)
    camera = result.scenario.measurement.camera
    segments = len(result.scenario.interceptions)
    assert len(names) == 2 * 3 * segments  # colour + depth at start, half-way and tf of each segment
    from ptint_drake.systems.perception.frame_images import CAPTION_HEIGHT, SCALE_WIDTH

    for name in names:
        whole = np.asarray(Image.open(tmp_path / name))
        depth = name.endswith("_depth.png")
        width = camera.width + (SCALE_WIDTH if depth else 0)
        assert whole.shape[:2] == (CAPTION_HEIGHT + camera.height, width), name
        caption = whole[:CAPTION_HEIGHT, :, :3]
        assert np.count_nonzero(np.all(caption < 100, axis=-1)) > 200, f"{name}: no caption text"
        if depth:  # the scale's ramp: bright at its top, dark at its bottom
            ramp = whole[CAPTION_HEIGHT + 20: -36, camera.width + 12, 0].astype(int)
            assert ramp[0] > 200 and ramp[-1] < 50 and np.all(np.diff(ramp) <= 0), name
        image = whole[CAPTION_HEIGHT:, :camera.width]  # the camera's own pixels
        if depth:
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
    assert world.figure_files(result.scenario) == ["picks.png", "timeline.png", "estimates.png"]
    tasks = world.view_tasks(result.scenario, result.series, result.metrics, tmp_path, True, False, False)
    assert [task[0] for task in tasks] == ["picks", "timeline", "estimates", "camera_frames"]
    for task in tasks[1:]:
        world.draw_view(*task)
    assert (tmp_path / "estimates.png").stat().st_size > 10_000 and (tmp_path / "timeline.png").is_file()
    assert 0.0 <= first_fit_time(result.series, 0) < 0.2  # the part is in view from the start
    # the first frame's good fit and, in both, the estimate the pick aimed at (at the grasp the
    # fingers hide the part: no good fit there)
    for label, marks in (("pick0_first_fit", (GOOD, ESTIMATE)), ("pick0_grasp", (ESTIMATE,))):
        color = np.asarray(Image.open(tmp_path / "frames" / f"{label}_color.png"))[:, :, :3]
        for rgb in marks:
            assert np.count_nonzero(np.all(color == rgb, axis=-1)) >= 12, (label, rgb)
        assert (tmp_path / "frames" / f"{label}_depth.png").exists()


def _recording(html: str) -> tuple[list[dict], dict]:
    """The meshcat commands of a recorded page (msgpack; typed arrays as (code, bytes)) and its
    animation's tracks: {path: {property: {frame: value}}}."""
    import base64
    import re

    msgpack = pytest.importorskip("msgpack")
    payloads = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    commands = [msgpack.unpackb(base64.b64decode(p), ext_hook=lambda code, data: (code, data))
                for p in payloads]
    animation = next(c for c in commands if c.get("type") == "set_animation")
    tracks = {a["path"]: {tr["name"]: {k["time"]: k["value"] for k in tr["keys"]}
                          for tr in a["clip"]["tracks"]} for a in animation["animations"]}
    return commands, tracks


def _visible_at(track: dict, frame: int) -> bool:
    """A visibility track's value at ``frame``: its last key at or before it (a discrete track)."""
    keys = sorted(f for f in track[".visible"] if f <= frame)
    return bool(track[".visible"][keys[-1]]) if keys else True


def _truth_at(series: dict, part: int, t: float) -> tuple[np.ndarray, np.ndarray]:
    times = np.asarray(series["t"])
    row = np.asarray(series[f"part_true_{part}"])[min(int(np.searchsorted(times, t)), len(times) - 1)]
    return row[0:3], row[3:12].reshape(3, 3)


def test_a_camera_pick_replay_shows_the_clouds_at_their_frames_and_the_estimate_beside_the_part(tmp_path):
    from ptint_drake.worlds.pick.camera_frames import pick_instants
    from ptint_drake.worlds.pick.views import GRASP_TAIL
    from ptint_drake.worlds.registry import world_of

    result = run_cached("conveyor_pick_place_rgbd")
    series, metrics = result.series, result.metrics
    world = world_of(result.scenario)
    task = world.view_tasks(result.scenario, series, metrics, tmp_path, False, True, False)[0]
    assert task[0] == "pick_replay"
    world.draw_view(*task)
    html = (tmp_path / "replay.html").read_text()
    assert html.startswith("<!DOCTYPE html>") and len(html) < 4_000_000
    commands, tracks = _recording(html)
    fps, replay_t = 30.0, np.asarray(series["replay_t"])
    half = 0.5 * np.asarray(result.scenario.pick.parts[0].size)
    instants = pick_instants(series, metrics)
    assert [label for label, _, _ in instants] == ["pick0_first_fit", "pick0_grasp"]
    frame_of = {label: float(replay_t[np.argmin(np.abs(replay_t - t))]) for label, _, t in instants}
    # each cloud stays until the next drawn for its pick (the first fit's until the grasp's frame),
    # the grasp's as long as the estimate (GRASP_TAIL)
    shown_for = {"pick0_first_fit": frame_of["pick0_grasp"] - frame_of["pick0_first_fit"],
                 "pick0_grasp": GRASP_TAIL}
    assert shown_for["pick0_first_fit"] > 1.0  # most of the approach, not a quarter second
    for label, part, t in instants:
        path = f"/drake/camera/clouds/{label}"
        cloud = next(c for c in commands if c.get("type") == "set_object" and c["path"] == path)
        _, data = cloud["object"]["geometries"][0]["data"]["attributes"]["position"]["array"]
        points = np.frombuffer(data, dtype="<f4").reshape(-1, 3)
        assert 0 < len(points) <= 5000, (label, len(points))
        t_frame = float(replay_t[np.argmin(np.abs(replay_t - t))])  # the replay state rendered
        x, R = _truth_at(series, part, t_frame)
        local = (points - x) @ R  # in the simulated part's frame
        if label.endswith("first_fit"):  # the part alone: on it, its top face seen whole
            assert np.all(np.abs(local) <= half + 0.002), np.abs(local).max(axis=0)
            top = local[np.abs(local[:, 2] - half[2]) <= 0.003]
            assert len(top) > 100 and np.linalg.norm(top[:, :2].mean(axis=0)) <= 0.003, top.mean(axis=0)
        else:  # the fingers beside it in its band: half the points at least on the part
            assert np.mean(np.all(np.abs(local) <= half + 0.003, axis=1)) >= 0.5
        on = [f for f in range(len(replay_t)) if _visible_at(tracks[path], f)]
        assert on and on[0] == int(np.floor(t_frame * fps + 1e-9)), (label, on[:3])
        assert on == list(range(on[0], on[-1] + 1))  # one stretch
        assert len(on) / fps == pytest.approx(shown_for[label], abs=1.5 / fps)
    # the estimate: a track over the run, what the series logged, near the part until the grasp
    track = tracks["/drake/estimates/part_0"]
    assert len(track[".position"]) >= 0.9 * len(replay_t)
    estimate, times = np.asarray(series["part_estimate_0"]), np.asarray(series["t"])
    grasp = metrics["picks"][0]["t_grasp_prescribed"]
    frame_t = {}
    for t in replay_t:  # a frame's key holds the last replay state in it
        frame_t[int(np.floor(t * fps))] = float(t)
    for frame, p in track[".position"].items():
        t = frame_t[frame]
        k = min(int(np.searchsorted(times, t)), len(times) - 1)
        assert np.allclose(p, estimate[k, 0:3], atol=1e-6), frame
        assert _visible_at(track, frame) == (t <= grasp + GRASP_TAIL), frame
        if 0.5 <= t <= grasp:  # fitted (the first fit is at ~0.03 s) and not yet in the hand
            assert np.linalg.norm(np.asarray(p) - _truth_at(series, 0, t)[0]) <= 0.003, t
    assert {f"/drake/estimates/part_0/triad/{a}" for a in "xyz"} <= {c.get("path") for c in commands}


def test_a_pick_replay_without_a_camera_draws_no_clouds_or_estimates(tmp_path):
    """The same run's motion replayed for the scenario without its camera: the page has neither."""
    import dataclasses

    from ptint_drake.worlds.pick.views import write_pick_replay

    result = run_cached("conveyor_pick_place_rgbd")
    plain = dataclasses.replace(result.scenario, measurement=None)
    write_pick_replay(plain, result.series, result.metrics, tmp_path / "replay.html")
    commands, tracks = _recording((tmp_path / "replay.html").read_text())
    paths = {c.get("path") or "" for c in commands} | set(tracks)
    assert not any("/camera/" in p or "/estimates/" in p for p in paths)
    assert any("/drake/visualizer/" in p for p in tracks)  # the robot is replayed
