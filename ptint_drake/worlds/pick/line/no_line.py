"""The pick run of a task list: ``PickRun`` (``worlds.pick.world``) calls a line's hooks
(``line.driver.LineDriver``) at every stop; without a line, ``NoLine``'s do nothing."""

from __future__ import annotations


class NoLine:
    """The pick run of a task list: no line (``PickRun`` calls the same hooks; they do nothing)."""

    active = False

    def __init__(self, scenario):
        self.scenario = scenario

    def bind(self, built) -> None:
        pass

    def start(self, context) -> None:
        pass

    def restore(self, context) -> None:
        pass

    def stops(self, duration: float) -> list[float]:
        return []

    def at_stop(self, run, context, t: float) -> bool:
        return False

    def add_metrics(self, metrics: dict, series: dict) -> None:
        pass

    def planning(self):
        return None
