"""Issue 43: the controller side is built from the scenario's declared cell only.  The drive's
diagram (``hardware.drive.DriveDiagram``: targets, estimators, perception, gripper sequencer,
controller) is built twice from scenarios whose truth-side draws differ — the random placement
and the camera noise drawn from ``measurement.seed``, the parts' mass and friction, the camera's
calibration error and depth-noise scale — and the two must be configured identically: the same
systems, ports and connections, and the same default state and parameters in every system."""

from __future__ import annotations

import copy

import numpy as np
import pytest

from ptint_drake.hardware.drive import DriveDiagram
from ptint_drake.simulation.scenario import load_scenario


def _leaves(system):
    """The leaf systems of ``system``, sub-diagrams opened (the perception is one)."""
    if hasattr(system, "GetSystems"):
        for child in system.GetSystems():
            yield from _leaves(child)
    else:
        yield system


def _plain(value):
    """``value`` as a comparable plain value when it is a number, a string or a list of numbers
    (not an array: a system's work buffers are arrays allocated empty)."""
    if isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, (list, tuple)) and all(isinstance(v, (int, float)) for v in value):
        return list(value)
    return None


def configuration(diagram) -> list:
    """Every leaf system of ``diagram``: its path, type, ports, a Python system's own plain
    settings (numbers, strings, lists of numbers: e.g. a sampling period), and its default context's state
    and numeric parameters (abstract state: its type and, for plain values, the value)."""
    out = []
    context = diagram.CreateDefaultContext()
    context.SetTime(1e-4)
    for system in _leaves(diagram):
        sub = system.GetMyContextFromRoot(context)
        inputs = [system.get_input_port(i) for i in range(system.num_input_ports())]
        outputs = [system.get_output_port(i) for i in range(system.num_output_ports())]
        ports = [(p.get_name(), p.size()) for p in inputs + outputs]
        own = {k: _plain(v) for k, v in sorted(vars(system).items()) if _plain(v) is not None}
        state = [np.asarray(sub.get_continuous_state_vector().CopyToVector()).tolist()]
        state += [np.asarray(sub.get_discrete_state(i).value()).tolist()
                  for i in range(sub.num_discrete_state_groups())]
        state += [np.asarray(sub.get_numeric_parameter(i).value()).tolist()
                  for i in range(sub.num_numeric_parameter_groups())]
        for i in range(sub.num_abstract_states()):
            value = sub.get_abstract_state(i).get_value()
            plain = isinstance(value, (int, float, str, list, dict, tuple))
            state.append(value if plain else type(value).__name__)
        out.append((system.GetSystemPathname(), type(system).__name__, ports, own, state))
    return out


def _drawn(name: str, change) -> object:
    scenario = copy.deepcopy(load_scenario(name))
    change(scenario)
    return scenario


def _seed(scenario):
    scenario.measurement.seed = 7


def _parts(scenario):
    for part in scenario.pick.parts:
        part.mass, part.friction = 0.9, 0.1


def _camera(scenario):
    scenario.measurement.camera.pose_error = [0.001, -0.001, 0.0005, 0.2, -0.1, 0.1]
    scenario.measurement.camera.depth_noise_scale = 2.0


@pytest.mark.parametrize("change", [_seed, _parts, _camera],
                         ids=["measurement.seed", "parts", "camera error"])
def test_the_drive_is_configured_the_same_whatever_the_truth_draws(change):
    base = configuration(DriveDiagram(load_scenario("conveyor_pick_place_rgbd"))[0])
    drawn = configuration(DriveDiagram(_drawn("conveyor_pick_place_rgbd", change))[0])
    assert len(base) == len(drawn) > 15
    for a, b in zip(base, drawn):
        assert a == b, (a[0], a[1])


def test_the_comparison_sees_a_declared_change():
    """The check can fail: a change of what the cell declares (the camera's rate) shows."""
    def declared(scenario):
        scenario.measurement.rate_hz = 15.0

    base = configuration(DriveDiagram(load_scenario("conveyor_pick_place_rgbd"))[0])
    other = configuration(DriveDiagram(_drawn("conveyor_pick_place_rgbd", declared))[0])
    assert base != other
