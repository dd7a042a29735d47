"""catch_toss_iiwa14_rgbd end to end (issue 46): the ball seen only by the rendered RGB-D camera
(RgbdSensor on VTK, 60 Hz, 424 × 240, the D415-style depth noise; the ball's centre fitted in each
depth frame, ``worlds/catch/ball_camera.py``) is caught, and the replay (``worlds/catch/views.py``)
shows the ball, its estimate, the predicted catch point as it is revised, and the hand."""

from __future__ import annotations

import base64
import re

import numpy as np
import pytest

from ptint_drake.simulation.scenario import LoadedScenario
from ptint_drake.worlds.catch.views import FPS, write_catch_replay
from ptint_drake.worlds.runner import simulate

THROW = 1


@pytest.fixture(scope="module")
def rgbd_run():
    return simulate(LoadedScenario.load("catch_toss_iiwa14_rgbd", [f"catch.throw={THROW}",
                                                                   f"measurement.seed={THROW}"]).scenario)


def test_a_throw_seen_by_the_rendered_camera_is_caught(rgbd_run):
    c = rgbd_run.metrics["catch"]
    assert c["outcome"] == "caught" and rgbd_run.metrics["status"] == "ok"
    assert c["error_at_catch_m"] < 0.01  # the hand's tip against the true ball centre at t_catch
    t, x, estimate = (np.asarray(rgbd_run.series[k]) for k in ("t", "plant_state", "estimate"))
    flight = (t > 0.3) & (t < c["t_catch"] - 0.05)
    error = np.linalg.norm(estimate[flight, 0:3] - x[flight, 13:16], axis=1)
    assert np.median(error) < 0.005  # the fit of the depth frames' centres tracks the true ball


def _recording(html: str) -> tuple[set, dict]:
    """The page's drawn objects and its animation {path: {property: {frame: value}}}."""
    msgpack = pytest.importorskip("msgpack")
    payloads = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    commands = [msgpack.unpackb(base64.b64decode(p), ext_hook=lambda code, data: (code, data))
                for p in payloads]
    animation = next(c for c in commands if c.get("type") == "set_animation")
    drawn = {c["path"] for c in commands if c.get("type") == "set_object"}
    return drawn, {a["path"]: {tr["name"]: {k["time"]: k["value"] for k in tr["keys"]}
                               for tr in a["clip"]["tracks"]} for a in animation["animations"]}


def test_the_replay_shows_the_ball_its_estimate_the_catch_point_and_the_hand(rgbd_run, tmp_path):
    write_catch_replay(rgbd_run.scenario, rgbd_run.series, rgbd_run.metrics, tmp_path / "replay.html")
    drawn, animation = _recording((tmp_path / "replay.html").read_text())
    assert {f"/drake/catch/{n}" for n in ("ball_path", "hand_path", "estimate", "catch_point")} <= drawn
    plans = [(p["t_plan"], np.asarray(p["point"])) for p in rgbd_run.metrics["catch"]["plans"]]
    keys = animation["/drake/catch/catch_point"][".position"]
    assert keys and min(keys) / FPS >= plans[0][0] - 1.0 / FPS  # not before the first plan
    for frame, value in keys.items():  # at each frame, the newest plan's point
        newest = [p for t_plan, p in plans if t_plan <= frame / FPS + 1.0 / FPS]
        assert np.allclose(value, newest[-1], atol=1e-6)
    t, x = np.asarray(rgbd_run.series["t"]), np.asarray(rgbd_run.series["plant_state"])
    shown = animation["/drake/catch/estimate"][".position"]
    t_catch = rgbd_run.metrics["catch"]["t_catch"]
    near = [np.linalg.norm(np.asarray(v) - x[min(np.searchsorted(t, f / FPS), len(t) - 1), 13:16])
            for f, v in shown.items() if 0.3 < f / FPS < t_catch - 0.05]
    assert len(near) >= 5 and np.median(near) < 0.01  # the estimate drawn where the ball flew
