"""Every replay page explains itself and keeps playing: the interception and the pick world's
pages loop their recording, carry the time display, a pause / play button and a legend, draw the
floor and hide Meshcat's grid and axes; in headless Chromium the time display shows the time the
animation is at."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run_cached

ROOT = Path(__file__).resolve().parents[2]
LOOP_REPEAT = 2201  # three.js's LoopRepeat (LoopOnce is 2200)


def _commands(html: str) -> list[dict]:
    import base64  # noqa: PLC0415

    msgpack = pytest.importorskip("msgpack")
    payloads = re.findall(r'data:application/octet-binary;base64,([A-Za-z0-9+/=]+)"', html)
    return [msgpack.unpackb(base64.b64decode(p), ext_hook=lambda code, data: (code, data)) for p in payloads]


def _check_page(html: str, legend_words: list) -> list[dict]:
    from ptint_drake.views.replay import OVERLAY_ID, TIME_ID  # noqa: PLC0415

    assert f'id="{OVERLAY_ID}"' in html and f'id="{TIME_ID}"' in html and 'id="ptint-play"' in html
    overlay = html[html.index(f'id="{OVERLAY_ID}"'):]
    for word in legend_words:
        assert word in overlay, word
    commands = _commands(html)
    animation = next(c for c in commands if c.get("type") == "set_animation")
    assert animation["options"]["loopMode"] == LOOP_REPEAT and animation["options"]["repetitions"] > 1000
    # every track ends at the last frame: each path's clip loops with the same period
    ends = {a["path"]: max(k["time"] for tr in a["clip"]["tracks"] for k in tr["keys"])
            for a in animation["animations"]}
    assert len(set(ends.values())) == 1, sorted(set(ends.values()))
    hidden = {c["path"] for c in commands if c.get("type") == "set_property"
              and c.get("property") == "visible" and c.get("value") is False}
    assert {"/Grid", "/Axes"} <= hidden
    assert any(c.get("type") == "set_object" and c.get("path", "").endswith("/floor/plate") for c in commands)
    return commands


def test_interception_replay_loops_with_time_legend_and_floor(tmp_path):
    from ptint_drake.robot.plant import resolve_model  # noqa: PLC0415
    from ptint_drake.views.replay import write_replay  # noqa: PLC0415

    result = run_cached("curve_b075_tf15")
    path = tmp_path / "replay.html"
    write_replay(result.series, result.metrics, str(resolve_model("rvm1")), path, end_effector="tool",
                 title="curve_b075_tf15: ok")
    html = path.read_text()
    _check_page(html, ["curve_b075_tf15: ok", "object 0", "prescribed time 1.5 s", "yellow marker",
                       "trail", "floor"])
    assert "conveyor belts" not in html[html.index('id="ptint-overlay"'):]  # no belts in this run


@pytest.mark.slow
def test_pick_replay_time_display_follows_the_animation_in_chromium(tmp_path):
    """The camera pick's page: the cloud, the estimate's outline and the floor explained; paused
    and sought to 1.0 s in headless Chromium, the time display reads 1.00 s."""
    from ptint_drake.worlds.registry import world_of  # noqa: PLC0415

    result = run_cached("conveyor_pick_place_rgbd")
    world = world_of(result.scenario)
    task = world.view_tasks(result.scenario, result.series, result.metrics, tmp_path, False, True, False)[0]
    world.draw_view(*task)
    page = tmp_path / "replay.html"
    _check_page(page.read_text(), ["1 of 1 placed", "point cloud", "yellow outline", "floor"])
    sys.path.insert(0, str(ROOT / "scripts"))
    from replay_screenshots import CHROMIUM, shoot  # noqa: PLC0415

    if not Path(CHROMIUM).exists():
        pytest.fail("chromium is missing: run scripts/setup.sh")
    from playwright.sync_api import sync_playwright  # noqa: PLC0415

    shots = shoot(page, (1.0,), "pick", tmp_path)
    assert shots[0].stat().st_size > 10_000
    with sync_playwright() as p:
        from replay_screenshots import BROWSER_ARGS  # noqa: PLC0415

        browser = p.chromium.launch(executable_path=CHROMIUM, args=BROWSER_ARGS)
        tab = browser.new_page(viewport={"width": 800, "height": 500})
        tab.goto(page.as_uri())
        tab.wait_for_function("viewer.animator.actions.length > 0", timeout=60_000)
        tab.click("#ptint-play")
        tab.evaluate("viewer.animator.seek(1.0)")
        tab.wait_for_timeout(300)
        assert tab.inner_text("#ptint-time") == "t = 1.00 s"
        assert tab.inner_text("#ptint-play") == "play"
        tab.click("#ptint-play")  # plays on: the time moves
        tab.wait_for_timeout(700)
        later = float(tab.inner_text("#ptint-time").split()[2])
        browser.close()
    assert later != pytest.approx(1.0, abs=0.05)
    assert np.isfinite(later)
