"""``ptint bench --floors``' diagrams of the interception world: the scenario's station with
something else in the controller's place, to take the cost of a derivative evaluation apart
(``studies.benchmark.floors``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.config.schema import Scenario
from ptint_drake.controllers.slot import TargetView, measures_orientation
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.worlds.interception.station import MakeStation, Station
from ptint_drake.worlds.stateless_derivatives import install_stateless_derivatives


@dataclass
class FloorBuilt:
    """A floor diagram and its station."""

    diagram: object
    station: Station
    simulator_config: object  # the scenario's (``worlds.runner.make_simulator`` reads it)


class _ZeroTorque(LeafSystem):
    """A Python controller that does nothing: reads the plant state, outputs zero actuation
    (what any Python LeafSystem in the loop costs per derivative evaluation).  With ``extra``
    (sizes) it has inputs ``target_0`` … too and reads them as well (the camera floor: what a
    controller fed by the camera path costs before it computes anything)."""

    def __init__(self, n_state: int, n_actuation: int, extra=()):
        super().__init__()
        self._state_in = self.DeclareVectorInputPort("state", n_state)
        self._extra = [self.DeclareVectorInputPort(f"target_{i}", size) for i, size in enumerate(extra)]
        self._zero = np.zeros(n_actuation)
        self.DeclareVectorOutputPort("u", n_actuation, self._calc_with_targets if extra else self._calc)

    def _calc(self, context, output):
        self._state_in.Eval(context)
        output.SetFromVector(self._zero)

    def _calc_with_targets(self, context, output):
        self._state_in.Eval(context)
        for port in self._extra:
            port.Eval(context)
        output.SetFromVector(self._zero)


def floor_diagram(scenario: Scenario, kind: str, schedule: Schedule):
    """The scenario's station with ``kind`` in the controller's place: ``cpp`` (a Drake
    ConstantVectorSource), ``python`` (``_ZeroTorque``), ``python_camera`` (``_ZeroTorque``
    reading the camera path's target, and target rotation when the cameras measure one: the
    cameras, estimators and selectors the controller gets, ``controllers.slot.TargetView``) or
    ``controller`` is the world's ``build(scenario, log=False)``)."""
    builder = DiagramBuilder()
    station = MakeStation(scenario)
    system = builder.AddSystem(station.diagram)
    n_act = station.plant.num_actuators()
    if kind == "cpp":
        source = builder.AddSystem(ConstantVectorSource(np.zeros(n_act)))
    else:
        ports = []
        if kind == "python_camera":
            view = TargetView(builder, system, scenario, schedule, station.true_targets)
            measured = measures_orientation(scenario, station.true_targets)
            ports = [view.port()] + ([view.rotation_port()] if measured else [])
        source = builder.AddSystem(_ZeroTorque(station.plant.num_multibody_states(), n_act,
                                               [p.size() for p in ports]))
        builder.Connect(system.GetOutputPort("state"), source.get_input_port(0))
        for i, port in enumerate(ports):
            builder.Connect(port, source.get_input_port(1 + i))
    builder.Connect(source.get_output_port(), system.GetInputPort("actuation"))
    diagram = builder.Build()
    install_stateless_derivatives(diagram)  # the same treatment as ``build`` gives the controller
    return FloorBuilt(diagram, station, scenario.simulator)


