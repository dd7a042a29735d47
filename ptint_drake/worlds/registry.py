"""The worlds, and which one a scenario belongs to: the only module that imports them.

A scenario belongs to the world whose settings block it has (``World.block``: ``pick`` → the
pick world); a scenario with none of those blocks belongs to the interception world.  A third
world is one package under ``worlds/`` and one line in ``WORLDS``.
"""

from __future__ import annotations

from ptint_drake.config.schema import Scenario
from ptint_drake.systems.schedule import Schedule
from ptint_drake.worlds.base import RunResult, World
from ptint_drake.worlds.interception.checks import TARGET_KINDS
from ptint_drake.worlds.interception.world import InterceptionWorld
from ptint_drake.worlds.pick.world import PickWorld

WORLDS: dict[str, World] = {w.name: w for w in (
    InterceptionWorld(),  # the default: scenarios without another world's block
    PickWorld(),
)}

__all__ = ["TARGET_KINDS", "WORLDS", "RunResult", "World", "objects_of", "schedule_of", "world_of",
           "world_named"]


def world_of(scenario: Scenario) -> World:
    """The world of ``scenario``: the one whose ``block`` it sets, else the default world."""
    for world in WORLDS.values():
        if world.block is not None and getattr(scenario, world.block) is not None:
            return world
    return next(w for w in WORLDS.values() if w.block is None)


def world_named(name: str) -> World:
    """A world by its name (what a picklable view task carries)."""
    return WORLDS[name]


def schedule_of(scenario: Scenario) -> Schedule:
    """The interceptor's segments of ``scenario``, from its world."""
    return world_of(scenario).schedule(scenario)


def objects_of(scenario: Scenario) -> list:
    """The analytic motions of ``scenario``'s objects, from its world ([] where none exist)."""
    return world_of(scenario).objects(scenario)
