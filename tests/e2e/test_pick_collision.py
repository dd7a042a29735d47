"""Issue 33: a link or finger that runs into something during a pick is reported, never ``ok``."""

# a 4 × 4 cm bar ("gantry", a belt standing still) across the carry from the belt to the tray, its
# underside 17 cm high: the approach and descend keep clear of it (so the clearance check passes),
# the carrying hand runs into it
GANTRY = ("pick: {belts: [{name: belt, center: [0.30, 0.0, 0.135], direction: [0.0, 1.0, 0.0], speed: 0.1}, "
          "{name: gantry, center: [0.195, 0.16, 0.19], direction: [-0.6, 0.8, 0.0], speed: 0.0, "
          "length: 0.04, width: 0.04}]}")


def test_a_hand_carried_into_an_obstacle_is_a_collision_with_it(run):
    m = run("conveyor_pick_place", GANTRY).metrics
    assert m["status"] != "ok"
    assert m["picks"][0]["collision_with"] == ["gantry"], m["picks"][0]
    assert "pick 0: collision with gantry" in m["reasons"], m["reasons"]
