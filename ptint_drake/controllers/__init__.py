"""The controller slot: one registry of the package's controllers, and users' own (plugins).

Every controller is one module here: its settings (a config dataclass, read from the scenario's
``controller`` block), its ``Add…(slot, config, target)`` that adds it to a diagram and wires
it to the station (``slot.ControllerSlot``: ``state`` in, ``actuation`` out; ``slot.TargetView``:
the target as the controller may see it), and its telemetry (``slot.ControllerHandles``).
Everything else — the scenario schema's ``controller.<name>`` blocks, the validation of
``controller.type``, ``ptint compare``'s default list, the command line's help and the report's
text — is read from ``REGISTRY``.  Adding a controller to the package = one module plus one
line below.  A user's own controller needs no edit at all: ``type: "module:Class"``
(``plugin``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.controllers import ct_quintic, pd, plugin, ptsmc, smc
from ptint_drake.controllers.hold import AddActuationHold, held_telemetry
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, uses_analytic_targets

__all__ = ["REGISTRY", "CONTROLLERS", "ControllerType", "ControllerHandles", "ControllerSlot",
           "TargetView", "AddControllerTo", "check_controller", "controller_type",
           "uses_analytic_targets", "describe", "known_type"]


@dataclass(frozen=True)
class ControllerType:
    """One entry of the registry."""

    name: str  # the value of ``controller.type``
    summary: str  # one line for the help and the report
    add: Callable  # add(slot, config, target) -> ControllerHandles
    config: Optional[type] = None  # its own settings, the scenario block ``controller.<name>``
    settings: Optional[Callable] = None  # scenario controller block -> what ``add`` takes
    model_based: bool = False

    def settings_of(self, block):
        """What ``add`` takes, from the scenario's ``controller`` block."""
        if self.settings is not None:
            return self.settings(block)
        return getattr(block, self.name)


def _entry(module, add: Callable) -> ControllerType:
    return ControllerType(module.NAME, module.SUMMARY, add, getattr(module, "CONFIG", None),
                          getattr(module, "settings_of", None), getattr(module, "MODEL_BASED", False))


REGISTRY: dict[str, ControllerType] = {e.name: e for e in (
    _entry(ptsmc, ptsmc.AddPtsmc),  # the paper's
    _entry(pd, pd.AddPd),
    _entry(smc, smc.AddSmc),
    _entry(ct_quintic, ct_quintic.AddCtQuintic),
)}
CONTROLLERS = tuple(REGISTRY)


def known_type(type_: str) -> bool:
    """A registered name or a plugin's ``module:Class``."""
    return type_ in REGISTRY or plugin.is_plugin(type_)


def controller_type(type_: str) -> ControllerType:
    """The registry's entry of ``type_``, or for a plugin's ``module:Class`` an entry whose
    ``add`` adapts the plugin's constructor (``plugin.AddPlugin``): every controller is built by
    the same ``add(slot, settings, target)`` path."""
    entry = REGISTRY.get(type_)
    if entry is not None:
        return entry
    return ControllerType(type_, f"a user's controller ({plugin.FORM})",
                          functools.partial(plugin.AddPlugin, type_=type_), settings=plugin.plugin_params)


def describe() -> str:
    """One line per registered controller, and the plugin form (for help texts)."""
    lines = [f"{e.name}: {e.summary}" for e in REGISTRY.values()]
    return "\n".join(lines + [f"module:Class: your own controller, {plugin.FORM}"])


def check_controller(scenario) -> None:
    """Before any run: a plugin must import, construct and have the right ports (ScenarioError)."""
    if scenario.controller.type not in REGISTRY:
        plugin.check(scenario.controller.type, scenario)


def AddControllerTo(builder: DiagramBuilder, *, plant, frame, schedule, state, actuation, scenario,
                    target: TargetView, targets: list = ()) -> ControllerHandles:
    """Add ``scenario.controller.type`` between the ports ``state`` (the arm's [q; v]) and
    ``actuation`` (its torques, through the drive's hold when ``controller.control_period`` > 0,
    ``hold``), aiming at ``target``; ``plant`` and ``frame``: the arm's kinematics and end
    effector; ``targets``: the world's analytic objects ([] where none).  Each world wires its
    station to these ports (``worlds``)."""
    block = scenario.controller
    held = AddActuationHold(builder, actuation, block.control_period) if block.control_period > 0 else None
    slot = ControllerSlot(builder=builder, plant=plant, frame=frame, schedule=schedule, state=state,
                          actuation=held.get_input_port() if held is not None else actuation,
                          initial_q=np.radians(scenario.robot.initial_q_deg), scenario=scenario,
                          targets=list(targets))
    entry = controller_type(block.type)
    handles = entry.add(slot, entry.settings_of(block), target)
    handles.model_based = entry.model_based
    return handles if held is None else held_telemetry(handles, held, plant.MakeActuationMatrix())
