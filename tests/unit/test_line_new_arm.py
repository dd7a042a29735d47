"""Session 52, a line taken to the iiwa 14 (tests/line_iiwa14.yaml) as a new user writes it: a cell
where the min-tf model finds no cycle for the capacity estimate is warned, not raised, and a kept
task to a bin is planned again at the yaw it grasped at."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line import checks
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.cycle import LineCycles
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.line.view import LineView
from ptint_drake.worlds.pick.line.watch import AFTER, ahead
from ptint_drake.worlds.pick.phase_time import NoTfFits

LINE_BIN = str(Path(__file__).resolve().parents[1] / "line_bin.yaml")


def test_a_cell_with_no_cycle_is_warned_and_the_run_goes_on(monkeypatch):
    scenario, _ = line_scenario(load_scenario("line_short"))

    def no_cycle(*_args, **_kwargs):
        raise NoTfFits("no top-down posture along the way from [0.25, 0.1, 0.2] m to [0.25, 0.1, 0.15] m")

    class Driver:  # what line_warnings reads of a bound LineDriver
        cycles = LineCycles(scenario)
        view = LineView(scenario)

    Driver.scenario = scenario
    monkeypatch.setattr(checks, "estimate", no_cycle)
    (warning,) = [w for w in checks.line_warnings(scenario, Driver()) if "capacity" in w]
    assert warning.startswith("pick.line: the arm's capacity could not be estimated (no top-down posture")
    assert warning.endswith("the run goes on") and "\n" not in warning


def test_a_kept_bin_tasks_phases_are_planned_again_at_the_yaw_it_grasped_at():
    """``watch.ahead`` on a task to a bin (no ``place_yaw``: the tool keeps its grip's yaw over a
    bin) plans its phases after the grasp again; before session 52 it raised a TypeError (the
    iiwa 14's line, tests/line_iiwa14.yaml, at its first drift)."""
    scenario, _ = line_scenario(load_scenario(LINE_BIN))
    scenario.pick.tasks = [PickTaskConfig(part="disc_0", bin="bin", grip_yaw=0.3, start=0.5)]
    driver = SimpleNamespace(scenario=scenario, cycles=LineCycles(scenario), straight={})
    disc = Track(0, "disc", "conveyor", (0.25, -0.05, 0.15), -0.05, (0.0, 1.0, 0.0), 0.1, (1.0, 0.0, 0.0),
                 0.03, 0.015)
    assert ahead(driver, 0.5, 0, disc, (np.array([0.13, 0.2, 0.2]), 0.3)) == {}
    assert set(driver.straight[0]) == set(AFTER) and all(tf > 0.0 for tf in driver.straight[0].values())


def test_the_iiwa_s_capacity_is_estimated_on_the_yaw_branch_its_tool_starts_on():
    """The estimate's cycle starts on the slot's (a bin: yaw 0's) branch modulo π nearest the
    tool's yaw at the initial posture — the iiwa's is π, where at yaw 0 Drake's IK found no
    top-down posture beside its belt and the estimate failed (session 52: a warning instead of a
    number).  Measured: 5.9 picks per minute, a 10.1 s cycle (its rated 14 kg payload planned)."""
    from ptint_drake.worlds.pick.line.cycle import estimate
    from ptint_drake.worlds.pick.world import PickRun

    line = PickRun(load_scenario(str(Path(__file__).resolve().parents[1] / "line_iiwa14.yaml"))).line
    assert abs(abs(line.cycles.model.initial_yaw()) - np.pi) < 0.1
    picks, cycle = estimate(line.scenario, line.view.window_at, line.cycles.model)
    assert 3.0 < picks < 12.0 and cycle == pytest.approx(60.0 / picks)
