"""What ``ptint run`` writes for a task with orientation (issue 19): the angle figure listed in
metrics.json, and the replay's frame triads on the gripper and the part."""

import json

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


def test_the_angle_figure_is_written_and_listed(short_yaw):
    m = json.loads((short_yaw / "metrics.json").read_text())
    assert m["figures"] == ["axes.png", "errors.png", "joints.png", "paths3d.png", "angle.png"]
    assert (short_yaw / "angle.png").stat().st_size > 10_000
    assert m["segments"][0]["e_rot_tf_deg"] <= 2.0
