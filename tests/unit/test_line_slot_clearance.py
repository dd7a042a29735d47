"""Issue 44, collision-free motions: a tray slot where the open fingers come down beside a belt is
warned before a line's run (``obstacles.slot_warnings``), naming the slot and the belt — the
bundled two-belt line's tray at x = 0.12 m put its column at x = 0.17 m 2 mm (by the hand's
cylinder) into the inner belt's side, and every place there touched that belt."""

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.obstacles import slot_warnings


def test_slots_beside_the_inner_belt_are_named_and_the_bundled_lines_have_none():
    scenario = load_scenario("line_two_belts")
    assert slot_warnings(scenario, 0.012) == []
    for name in ("line_two_belts_rgbd", "line_two_belts_step", "line_short"):
        assert slot_warnings(load_scenario(name), 0.012) == [], name
    scenario.pick.tray.center = [0.12, 0.24, 0.10]  # where it was
    found = slot_warnings(scenario, 0.012)
    assert [w.split(":")[0] for w in found] == [f"pick.tray.slots[{j}]" for j in (2, 5, 8, 11, 14)]
    assert all("belt 'inner'" in w and "collision with inner" in w for w in found)
