"""The worlds, and which one a scenario belongs to: the only module that imports them.

A scenario belongs to the world whose settings block it has (``World.block``: ``pick`` → the
pick world); a scenario with none of those blocks belongs to the interception world.  A third
world is one package under ``worlds/`` and one line in ``WORLDS`` — or a plugin: a scenario's
``world: {type: "module:Class", params: {...}}`` names a ``World`` subclass in the user's own
file, found like a plugin controller (``controllers.plugin.load_class``: the scenario's folder,
the current directory, ``PYTHONPATH``) and constructed once per process with no arguments.
"""

from __future__ import annotations

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.controllers.plugin import is_plugin, load_class, search_folders
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.worlds.base import RunResult, World
from ptint_drake.worlds.catch.world import CatchWorld
from ptint_drake.worlds.interception.checks import TARGET_KINDS
from ptint_drake.worlds.interception.world import InterceptionWorld
from ptint_drake.worlds.pick.world import PickWorld

WORLDS: dict[str, World] = {w.name: w for w in (
    InterceptionWorld(),  # the default: scenarios without another world's block
    PickWorld(),
    CatchWorld(),
)}

__all__ = ["TARGET_KINDS", "WORLDS", "RunResult", "World", "objects_of", "plugin_world", "schedule_of",
           "world_key", "world_of", "world_named"]


_PLUGINS: dict[str, World] = {}  # the plugin worlds constructed in this process, by type string


def plugin_world(type_: str, folders=()) -> World:
    """The plugin world ``module:Class`` (constructed once per process); ScenarioError (one line)
    when it cannot be imported or is not a ``World``."""
    world = _PLUGINS.get(type_)
    if world is not None:
        return world
    if not is_plugin(type_):
        raise ScenarioError(f"world.type: expected 'module:Class' (a World subclass in your own file), "
                            f"got {type_!r}")
    cls = load_class(type_, folders, field="world.type")
    if not issubclass(cls, World):
        raise ScenarioError(f"world.type: {type_!r} is not a ptint_drake.worlds.base.World subclass")
    try:
        world = cls()
    except Exception as exc:  # noqa: BLE001  (the user's constructor: one line)
        raise ScenarioError(
            f"world.type: constructing {type_!r} raised {type(exc).__name__}: {exc}") from None
    if not world.name or world.name in WORLDS:
        raise ScenarioError(f"world.type: {type_!r} needs a name of its own (World.name), got {world.name!r}")
    _PLUGINS[type_] = world
    return world


def world_key(scenario: Scenario) -> str:
    """What names ``scenario``'s world in a picklable task (``world_named``): a bundled world's
    name, or a plugin's type string."""
    return scenario.world.type if scenario.world is not None else world_of(scenario).name


def world_of(scenario: Scenario) -> World:
    """The world of ``scenario``: a plugin (``world``), the one whose ``block`` it sets, else the
    default world."""
    if scenario.world is not None:
        return plugin_world(scenario.world.type, search_folders(scenario))
    for world in WORLDS.values():
        if world.block is not None and getattr(scenario, world.block) is not None:
            return world
    return next(w for w in WORLDS.values() if w.block is None)


def world_named(name: str) -> World:
    """A world by ``world_key`` (what a picklable view task carries)."""
    return WORLDS[name] if name in WORLDS else plugin_world(name)


def schedule_of(scenario: Scenario) -> Schedule:
    """The interceptor's segments of ``scenario``, from its world."""
    return world_of(scenario).schedule(scenario)


def objects_of(scenario: Scenario) -> list:
    """The analytic motions of ``scenario``'s objects, from its world ([] where none exist)."""
    return world_of(scenario).objects(scenario)
