"""A user's own controller in the slot, from the user's own file (SPEC 5.5).

``controller: {type: "my_module:MyController", params: {Kp: 40.0, ...}}`` names a Drake
``LeafSystem`` class that is constructed as::

    MyController(plant=<finalized MultibodyPlant of the nominal robot model>,
                 end_effector=<frame name>, params=<dict: numbers, lists of numbers, strings>)

(``params`` also holds ``task``, the scenario's ``controller.task``, when that is ``pose`` or
``top_down``: issue 19; a position scenario's params are exactly its own.)

with input ports ``state`` (the arm's [q; v]) and ``target`` ([x_r, ẋ_r, ẍ_r] of the active
segment, ``signals.TARGET``, 9 values), optionally an input ``segment`` ([index, start, tf] of
the active segment, ``systems.task.active_segment``) and an input ``target_rotation`` ([R_r row-major,
ω_r, ω̇_r], 15 values: the object's orientation, or with a camera the rotation estimator's
estimate of it, as the paper's controller gets it), and an output ``actuation`` (one torque per
actuator of the arm, in the plant's actuator order).  ``plant`` is for the plugin's
kinematics; a plugin that uses its dynamics is model-based and should say so.

The module is looked up in the folder of the scenario file (``Scenario.plugin_folders``, set
when the file is loaded: the folders travel with the loaded scenario), then the current
directory, then ``sys.path`` (``PYTHONPATH``). A study hands the same folders to its worker
processes and Dask workers with each task (``studies.runner.run_tasks(folders=...)``,
``searching``). An import failure, a constructor that raises, a missing port or a port of the
wrong size is a ``ScenarioError`` naming the controller (exit 2 on the command line); an
exception raised inside the plugin while simulating ends that run as ``failed``.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Sequence

from ptint_drake.config.errors import ScenarioError
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, target_columns
from ptint_drake.robot.plant import nominal_plant
from ptint_drake.systems.task.active_segment import SIZE as SEGMENT_SIZE
from ptint_drake.systems.task.active_segment import ActiveSegment
from ptint_drake.systems.task.signals import TARGET_PORT_SIZE, TARGET_ROTATION_SIZE

PATTERN = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*:[A-Za-z_][A-Za-z0-9_]*$")
FORM = "'module:Class' (a LeafSystem in your own file)"

# the folders of the study a worker runs a task of (``searching``): set per task by the study
# runner, which hands each task its scenario's folders (``studies.runner.run_tasks(folders=...)``)
_TASK_FOLDERS: ContextVar[tuple] = ContextVar("ptint_plugin_task_folders", default=())


def is_plugin(type_: str) -> bool:
    """True for a ``module:Class`` type string (a user's controller)."""
    return bool(PATTERN.match(type_))


def search_folders(scenario=None) -> list[str]:
    """Where plugin modules are looked for before ``sys.path``: the folder of the file
    ``scenario`` was loaded from (``Scenario.plugin_folders``), the running task's folders
    (``searching``), then the current directory."""
    own = [str(f) for f in getattr(scenario, "plugin_folders", ())]
    return [*own, *(f for f in _TASK_FOLDERS.get() if f not in own), os.getcwd()]


@contextmanager
def searching(folders: Sequence[str]):
    """Look in ``folders`` too while the block runs (a study's task in a worker process)."""
    token = _TASK_FOLDERS.set(tuple(folders))
    try:
        yield
    finally:
        _TASK_FOLDERS.reset(token)


def _error(message: str):
    return ScenarioError(" ".join(message.split()))


def load_class(type_: str, folders: Sequence[str] = (), field: str = "controller.type") -> type:
    """The class named by ``module:Class``, its module looked for in ``folders`` first (then
    ``sys.path``); ScenarioError (one line, naming the scenario's ``field``) if it cannot be had."""
    module_name, _, class_name = type_.partition(":")
    saved = list(sys.path)
    sys.path[:0] = list(folders)
    try:
        module = importlib.import_module(module_name)
    except Exception as exc:  # any failure of the user's module is one line
        raise _error(f"{field}: cannot import {module_name!r} for {type_!r} "
                     f"({type(exc).__name__}: {exc}); looked in the scenario's folder, the "
                     f"current directory and PYTHONPATH") from None
    finally:
        sys.path[:] = saved
    cls = getattr(module, class_name, None)
    if not isinstance(cls, type):
        raise _error(f"{field}: {module_name!r} has no class {class_name!r} ({type_!r})")
    return cls


def plain_params(params: dict) -> dict:
    """The scenario's ``params`` as the plugin gets them: a text that YAML 1.1 left a string
    although it is a number (``1e-3``) becomes a float."""
    out = {}
    for key, value in params.items():
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                pass
        out[key] = value
    return out


def plugin_params(controller) -> dict:
    """The ``params`` of the ``controller`` block's plugin as the scenario gives them (before
    ``plain_params``): its own and, for a task with orientation, ``task`` (``controller.task``:
    pose or top_down)."""
    params = dict(controller.params)
    return params if controller.task == "position" else params | {"task": controller.task}


def make_plugin(type_: str, plant, end_effector: str, params: dict, folders: Sequence[str] = ()):
    """Construct the plugin (its module looked for in ``folders`` first) and check its ports
    against ``plant``; returns the system."""
    cls = load_class(type_, folders)
    try:
        system = cls(plant=plant, end_effector=end_effector, params=dict(params))
    except Exception as exc:
        raise _error(f"controller {type_}: constructing it raised {type(exc).__name__}: {exc}") from None
    sizes = {"state": plant.num_positions() + plant.num_velocities(), "target": TARGET_PORT_SIZE}
    optional = {"segment": SEGMENT_SIZE, "target_rotation": TARGET_ROTATION_SIZE}
    for name, size in (sizes | optional).items():
        if not _has_port(system, "input", name):
            if name in optional:
                continue
            raise _error(f"controller {type_}: needs an input port {name!r} ({size} values)")
        got = system.GetInputPort(name).size()
        if got != size:
            raise _error(f"controller {type_}: input port {name!r} has {got} values, needs {size}")
    nu = plant.num_actuators()
    if not _has_port(system, "output", "actuation"):
        raise _error(f"controller {type_}: needs an output port 'actuation' ({nu} values)")
    got = system.GetOutputPort("actuation").size()
    if got != nu:
        raise _error(f"controller {type_}: output port 'actuation' has {got} values, needs {nu}")
    return system


def _has_port(system, kind: str, name: str) -> bool:
    count = system.num_input_ports() if kind == "input" else system.num_output_ports()
    get = system.get_input_port if kind == "input" else system.get_output_port
    return any(get(i).get_name() == name for i in range(count))


def check(type_: str, scenario) -> None:
    """Import and construct the plugin of ``scenario`` once (before any run): ScenarioError if
    it cannot be used."""
    plant = nominal_plant(scenario)
    make_plugin(type_, plant, scenario.robot.end_effector, plain_params(plugin_params(scenario.controller)),
                search_folders(scenario))


def AddPlugin(slot: ControllerSlot, params: dict, target: TargetView, *, type_: str) -> ControllerHandles:
    """Add the user's controller ``type_`` to the slot (ports in the module docstring); the
    registry's adapter (``controllers.controller_type``) binds ``type_``."""
    builder = slot.builder
    system = make_plugin(type_, slot.nominal_plant(), slot.frame.name(), plain_params(params),
                         search_folders(slot.scenario))
    if not system.get_name():
        system.set_name(type_.partition(":")[2])
    builder.AddSystem(system)
    builder.Connect(slot.state, system.GetInputPort("state"))
    port = target.port()
    builder.Connect(port, system.GetInputPort("target"))
    if _has_port(system, "input", "segment"):
        clock = builder.AddNamedSystem("active_segment", ActiveSegment(slot.schedule))
        builder.Connect(clock.get_output_port(), system.GetInputPort("segment"))
    if _has_port(system, "input", "target_rotation"):  # the object's orientation (issue 19)
        builder.Connect(target.rotation_port(), system.GetInputPort("target_rotation"))
    builder.Connect(system.GetOutputPort("actuation"), slot.actuation)
    B = slot.plant.MakeActuationMatrix()

    def telemetry(logs: dict) -> dict:
        return {"tau": logs["actuation"] @ B.T} | target_columns(logs["target"])

    ports = {"actuation": system.GetOutputPort("actuation"), "target": port}
    notes = [f"{type_}: a user's controller (params {dict(params) or 'none'})"]
    return ControllerHandles(type_, ports, telemetry, notes, system=system, plugin=True)
