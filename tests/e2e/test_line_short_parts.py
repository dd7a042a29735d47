"""Parts shorter than the fingers allow at their centre (tests/line_short_parts.yaml: 20 mm
blocks; the bundled grippers' fingers reach 10 mm past the fingertip centre).  Gripped at the
centre, the fingertips touched the belt at every grasp and the tray at every place: each part
was counted placed with ``collision with feed, tray`` and the line said ok.  Now the tool grips
them 5 mm above the centre (``worlds/pick/config.grip_height``): placed within the criteria, no
collision, no warning of one."""

from pathlib import Path

import pytest

SCENARIO = str(Path(__file__).resolve().parents[1] / "line_short_parts.yaml")

pytestmark = pytest.mark.slow


def test_short_parts_are_placed_without_the_fingertips_touching_belt_or_tray(run):
    m = run(SCENARIO).metrics
    line = m["line"]
    assert m["status"] == "ok" and line["entered"] == line["placed"] == 2, m["reasons"]
    for pick in m["picks"]:
        assert pick["placed"] and pick["place_error_mm"] < 3.0
        assert not pick["collision"] and pick["collision_with"] == [], pick["collision_with"]
        assert pick["grip_force_N"] > 25.0  # (the fingertips on the belt had it at 19.6 N)
    assert not [w for w in m["warnings"] if "touched" in w], m["warnings"]
