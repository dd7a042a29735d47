"""Issue 33: a link or finger that runs into something during a pick is reported, never ``ok``;
issue 44: what the planning model sees in the way is gone around (``obstacles``), and what no via
clears is warned before the run, naming the bodies, and named as a collision during it."""

import pytest

# a 4 × 4 cm bar ("gantry", a belt standing still) across the carry from the belt to the tray, its
# underside 17 cm high: the approach and descend keep clear of it (so the clearance check passes);
# the straight carry runs the hand into it
BELT = "{name: belt, center: [0.30, 0.0, 0.135], direction: [0.0, 1.0, 0.0], speed: 0.1}"
GANTRY = ("pick: {belts: [" + BELT + ", {name: gantry, center: [0.195, 0.16, 0.19], "
          "direction: [-0.6, 0.8, 0.0], speed: 0.0, length: 0.04, width: 0.04}]}")
# the same bar as a wall from 0.17 m to 0.62 m: no via up to 0.3 m above the carry clears it
WALL = ("pick: {belts: [" + BELT + ", {name: gantry, center: [0.195, 0.16, 0.62], "
        "direction: [-0.6, 0.8, 0.0], speed: 0.0, length: 0.04, width: 0.04, thickness: 0.45}]}")


def test_a_bar_across_the_carry_is_gone_over_and_the_part_placed(run):
    """Before issue 44's planning model the carrying hand ran into the bar (``collision with
    gantry``); now the carry goes by a via above the slot and places the part."""
    m = run("conveyor_pick_place", GANTRY).metrics
    assert m["status"] == "ok", m["reasons"]
    pick = m["picks"][0]
    assert pick["placed"] and not pick["collision"], pick


@pytest.mark.slow
def test_a_wall_no_via_clears_is_warned_and_the_collision_named(run):
    m = run("conveyor_pick_place", WALL).metrics
    assert any("carry passes" in w and "'belt gantry'" in w and "no via above clears it" in w
               for w in m["warnings"]), m["warnings"]
    assert m["status"] != "ok"
    assert "gantry" in m["picks"][0]["collision_with"], m["picks"][0]
    assert any(r.startswith("pick 0: collision with") and "gantry" in r for r in m["reasons"]), m["reasons"]
