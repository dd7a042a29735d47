"""Session 53: a line spreads its drops over a bin's floor (``scene.bin_spots``,
``PickTaskConfig.bin_at``) — every part let go over the bin's centre stacked: a Panda line of
40 × 25 mm pucks into a 120 × 120 × 50 mm bin rested its third puck 12 mm above the walls, `not in
the bin`."""

from pathlib import Path

import numpy as np
import pytest

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.pick import BinConfig, PartConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.cell import place_positions, world_config
from ptint_drake.worlds.pick.scene import BIN_GAP, bin_spots
from ptint_drake.worlds.pick.tasks import check_tasks, pick_plan

BIN_PICK = str(Path(__file__).resolve().parents[1] / "bin_pick.yaml")
PUCK = PartConfig(name="puck", shape="cylinder", size=[0.04, 0.025], mass=0.05)
CUBE = PartConfig(name="cube", shape="box", size=[0.03, 0.03, 0.03], mass=0.1)


@pytest.mark.parametrize("part", [PUCK, CUBE], ids=["puck", "cube"])
@pytest.mark.parametrize("inner", [0.10, 0.12, 0.2])
def test_the_spots_keep_a_gap_between_parts_and_from_the_walls(part, inner):
    box = BinConfig(name="bin", center=[0.3, 0.35, 0.1], size=[inner, 0.8 * inner, 0.05])
    spots = np.array(bin_spots(box, part))
    extent = part.size[0] if part.shape == "cylinder" else np.hypot(*part.size[:2])
    for axis in (0, 1):
        assert np.all(np.abs(spots[:, axis]) + extent / 2 + BIN_GAP <= box.size[axis] / 2 + 1e-12) \
            or len(np.unique(spots[:, axis])) == 1  # (the centre alone where one does not fit)
    if len(spots) > 1:
        gaps = [np.linalg.norm(a - b) for i, a in enumerate(spots) for b in spots[i + 1:]]
        assert min(gaps) >= extent + BIN_GAP - 1e-12


def test_the_puck_bin_of_the_panda_line_holds_four_drop_points_not_one():
    box = BinConfig(name="reject", center=[0.3, 0.35, 0.1], size=[0.12, 0.12, 0.05])
    assert len(bin_spots(box, PUCK)) == 4
    assert bin_spots(BinConfig(name="b", size=[0.05, 0.05, 0.05]), PUCK) == [(0.0, 0.0)]


def test_a_task_s_bin_at_moves_its_carry_place_and_retreat_over_the_floor():
    scenario = load_scenario(BIN_PICK)
    before = place_positions(world_config(scenario), pick_plan(scenario.pick))
    scenario.pick.tasks[0].bin_at = [0.02, -0.015]
    plan = pick_plan(scenario.pick)
    phases = {seg.phase: seg for seg in plan.segments}
    for phase in ("carry", "place", "retreat"):
        assert phases[phase].offset[:2] == (0.02, -0.015)
    after = [p for p in place_positions(world_config(scenario), plan) if p is not None]
    assert np.allclose(after, [p for p in before if p is not None])  # (the offset is the segment's)


def test_a_bin_at_beyond_the_floor_is_one_line_naming_the_field():
    scenario = load_scenario(BIN_PICK)
    scenario.pick.tasks[0].bin_at = [0.06, 0.0]  # the bin is 0.10 m inside
    with pytest.raises(ScenarioError, match=r"^pick\.tasks\[0\]\.bin_at: \[0\.06, 0\.0\] m is not an"):
        check_tasks(scenario.pick)
