"""The catch world (issue 46) on the world seam: a scenario with a ``catch`` block."""

from __future__ import annotations

from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.verdict.metrics import Reason
from ptint_drake.worlds.base import World
from ptint_drake.worlds.catch.run import CatchRun


class CatchWorld(World):
    """A thrown ball caught in the hand at a time the planner chooses (``worlds.catch``)."""

    name = "catch"
    block = "catch"
    summary = "a thrown foam ball caught in the hand of the iiwa 14 with a WSG 50-110"

    def schedule(self, scenario) -> Schedule:
        c = scenario.catch
        return Schedule([Segment(0.0, c.sensing, c.beta), Segment(c.sensing, 0.6, c.beta)])

    def prepare(self, scenario, log: bool = True) -> CatchRun:
        return CatchRun(scenario, log)

    def reasons(self, metrics: dict, criteria) -> list:
        name = metrics.get("catch", {}).get("outcome")
        return [] if name == "caught" else [Reason(None, "catch", f"not caught: {name}")]

    def own_plant_step(self, scenario) -> float:
        return 0.001
