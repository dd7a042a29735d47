"""Issue 44: the pick replay shows the perception's tracks — each confirmed track a small sphere of
its own colour over its part at its estimated centre, moving with it (the tracks log), from its
confirmation to its end; two parts on one belt seen by the RGB-D camera (tests/two_parts_one_belt.yaml)."""

import base64
import re
from pathlib import Path

import numpy as np
import pytest

from ptint_drake.systems.perception.tracks import CONFIRM
from ptint_drake.worlds.pick.track_markers import MARK_ABOVE
from ptint_drake.worlds.pick.views import write_pick_replay

TWO_PARTS = str(Path(__file__).resolve().parents[1] / "two_parts_one_belt.yaml")
FPS = 30.0  # the pick replay's frame rate


def _recording(html: str) -> tuple[list[dict], dict]:
    """The page's meshcat commands and its animation: {path: {property: {frame: value}}}."""
    msgpack = pytest.importorskip("msgpack")
    payloads = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    commands = [msgpack.unpackb(base64.b64decode(p), ext_hook=lambda code, data: (code, data))
                for p in payloads]
    animation = next(c for c in commands if c.get("type") == "set_animation")
    return commands, {a["path"]: {tr["name"]: {k["time"]: k["value"] for k in tr["keys"]}
                                  for tr in a["clip"]["tracks"]} for a in animation["animations"]}


def _visible_at(keys: dict, frame: int) -> bool:
    before = [f for f in keys if f <= frame]
    return bool(keys[max(before)]) if before else False  # drawn hidden until its first key


def test_the_replay_shows_each_confirmed_track_over_its_part_moving_with_it(run, tmp_path):
    result = run(TWO_PARTS, ())
    series, metrics = result.series, result.metrics
    write_pick_replay(result.scenario, series, metrics, tmp_path / "replay.html")
    commands, animation = _recording((tmp_path / "replay.html").read_text())
    drawn = {c["path"]: c["object"]["materials"][0]["color"] for c in commands
             if c.get("type") == "set_object" and c["path"].startswith("/drake/tracks/")}
    bound = {name: ids[0] for name, ids in metrics["tracking"]["tracks_per_part"].items()}
    assert sorted(drawn) == sorted(f"/drake/tracks/track_{i}" for i in bound.values())  # confirmed only
    assert len(set(drawn.values())) == len(drawn)  # a colour per track
    times, replay_t = np.asarray(series["t"]), np.asarray(series["replay_t"])
    frame_t = {int(np.floor(t * FPS)): float(t) for t in replay_t}  # a frame's key: its last state
    period = 1.0 / result.scenario.measurement.rate_hz
    for k, part in enumerate(result.scenario.pick.parts):
        keys = animation[f"/drake/tracks/track_{bound[part.name]}"]
        task = next(j for j, p in enumerate(metrics["picks"]) if p["part_index"] == k)
        grasp = metrics["picks"][task]["t_grasp_prescribed"]
        shown = [f for f in sorted(keys[".position"]) if _visible_at(keys[".visible"], f)]
        assert frame_t[shown[0]] <= (CONFIRM - 1) * period + 2.0 / FPS  # from its confirmation
        switches = [bool(keys[".visible"][f]) for f in sorted(keys[".visible"])]
        switches = [on for j, on in enumerate(switches) if j == 0 or on != switches[j - 1]]
        assert switches in ([True], [False, True], [True, False], [False, True, False])  # one stretch
        checked = 0
        for frame in shown:
            t = frame_t[frame]
            if t > grasp - 0.5:  # under the arm and in the hand: the track coasts, the part is carried
                continue
            true = np.asarray(series[f"part_true_{k}"])[min(int(np.searchsorted(times, t)), len(times) - 1)]
            p = np.asarray(keys[".position"][frame])
            assert np.linalg.norm(p[:2] - true[:2]) <= 0.004, (part.name, t, p, true[:3])
            assert p[2] == pytest.approx(true[2] + 0.5 * part.size[2] + MARK_ABOVE, abs=0.003)
            checked += 1
        assert checked >= 10
        along = [keys[".position"][f][1] for f in shown]
        assert max(along) - min(along) >= 0.1  # it moves with its part along the belt
