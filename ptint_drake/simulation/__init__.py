"""Run a scenario: the public entry points (``docs/api.md``), over the one runner.

``simulate(scenario)`` runs it in its world (``worlds.runner``); ``build(scenario)`` gives the
world's diagram and handles without running it (``WorldRun``: ``diagram``, ``controller``);
``make_simulator(run)`` a ``Simulator`` of it with the world's integrator settings.
"""

from __future__ import annotations

from ptint_drake.config.schema import Scenario
from ptint_drake.worlds.base import RunResult, WorldRun
from ptint_drake.worlds.registry import world_of
from ptint_drake.worlds.runner import make_simulator, simulate

__all__ = ["RunResult", "WorldRun", "build", "make_simulator", "simulate"]


def build(scenario: Scenario, log: bool = True) -> WorldRun:
    """The scenario's diagram in its world, not yet simulated (``log``: with the loggers)."""
    return world_of(scenario).prepare(scenario, log)
