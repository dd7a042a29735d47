"""What ``ptint run`` writes for a task with orientation (issue 19): the angle figure listed in
metrics.json, and the replay's frame triads on the gripper and the part, which line up at tf."""

import base64
import json
import re

import numpy as np
import pytest
from test_cli import ptint

# conveyor_yaw cut to its second part (turned 30°) and 0.8 s: one top-down interception
ONE_PART = ("interceptions=[{start: 0.0, tf: 0.5, beta: 0.75, target: {linear: {start: [0.20, -0.23, 0.25], "
            "velocity: [0.0, 0.1, 0.0]}, orientation: {rpy_deg: [0.0, 0.0, 30.0]}}}]")


@pytest.fixture(scope="module")
def short_yaw(tmp_path_factory):
    out = tmp_path_factory.mktemp("yaw") / "run"
    done = ptint("run", "conveyor_yaw", "--set", "duration=0.8", "--set", ONE_PART, "--out", str(out),
                 "--quiet")
    assert done.returncode == 0, done.stderr
    return out


@pytest.mark.slow
def test_the_angle_figure_is_written_and_listed(short_yaw):
    m = json.loads((short_yaw / "metrics.json").read_text())
    assert m["figures"] == ["axes.png", "errors.png", "joints.png", "paths3d.png", "angle.png"]
    assert (short_yaw / "angle.png").stat().st_size > 10_000
    assert m["segments"][0]["e_rot_tf_deg"] <= 2.0


def _commands(html: str) -> list[bytes]:
    """The meshcat commands a recorded page replays (base64 msgpack payloads)."""
    payloads = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    return [base64.b64decode(m) for m in payloads]


def test_the_replay_draws_triads_that_line_up_at_tf(short_yaw):
    commands = _commands((short_yaw / "replay.html").read_text())
    for name in ("gripper", "object"):
        for axis in "xyz":
            assert any(f"/drake/triads/{name}/{axis}".encode() in c for c in commands), (name, axis)
    msgpack = pytest.importorskip("msgpack")
    animation = next(m for m in map(msgpack.unpackb, commands) if m.get("type") == "set_animation")
    tracks = {a["path"]: {tr["name"]: {k["time"]: k["value"] for k in tr["keys"]}
                          for tr in a["clip"]["tracks"]} for a in animation["animations"]}

    def angle_deg(frame: int) -> float:
        q = [np.asarray(tracks[f"/drake/triads/{n}"][".quaternion"][frame]) for n in ("gripper", "object")]
        return float(np.degrees(2.0 * np.arccos(min(1.0, abs(q[0] @ q[1])))))

    seg = json.loads((short_yaw / "metrics.json").read_text())["segments"][0]
    # 30 frames a second: frame 0 is the start, frame 15 is tf = 0.5 s
    assert angle_deg(0) == pytest.approx(seg["e_rot0_deg"], abs=0.01)
    assert angle_deg(15) == pytest.approx(seg["e_rot_tf_deg"], abs=0.01) and angle_deg(15) < 0.1
