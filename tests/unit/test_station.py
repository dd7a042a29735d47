"""The station owns its world: plant variants and the start pose hold in any diagram's default
context, so a user's own diagram around ``MakeStation`` simulates what ``ptint run`` does."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.robot.plant import make_plant
from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import ScenarioError, load_scenario
from ptint_drake.worlds.interception.station import MakeStation
from ptint_drake.worlds.interception.world import AddController
from ptint_drake.worlds.registry import schedule_of


def _scenario(mass_scale: float = 1.0, payload_kg: float = 0.0):
    scenario = load_scenario("curve_b075_tf15")
    scenario.duration = 1.5  # to tf: the error that matters
    scenario.plant.mass_scale, scenario.plant.payload_kg = mass_scale, payload_kg
    return scenario


def _mass_matrix(plant, q) -> np.ndarray:
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    return plant.CalcMassMatrix(context)


def test_a_users_diagram_with_only_the_station_and_the_controller_is_the_run():
    """MakeStation's diagram + the controller wired by hand + a plain Simulator from the
    default context: e(tf) is simulate()'s (mass × 1.5, which the station alone applies)."""
    scenario = _scenario(mass_scale=1.5)
    builder = DiagramBuilder()
    station = MakeStation(scenario)
    station_system = builder.AddSystem(station.diagram)
    AddController(builder, station_system, station, scenario)
    diagram = builder.Build()
    simulator = Simulator(diagram)
    ApplySimulatorConfig(scenario.simulator, simulator)
    context = simulator.get_mutable_context()
    station_context = station_system.GetMyContextFromRoot(context)
    q0 = station_system.GetOutputPort("state").Eval(station_context)[:station.plant.num_positions()]
    np.testing.assert_array_equal(q0, np.radians(scenario.robot.initial_q_deg))
    seg = schedule_of(scenario).segments[0]
    for t in (seg.start + 0.5 * seg.tf, seg.end):  # the stops simulate() makes
        simulator.AdvanceTo(t)
    plant = station.plant
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    x = frame.CalcPoseInWorld(plant.GetMyContextFromRoot(context)).translation()
    target = station_system.GetOutputPort("target").Eval(station_context)
    e_tf = float(np.linalg.norm(x - target[0:3]))
    expected = simulate(scenario, check=False).metrics["segments"][0]["e_tf_norm"]
    assert e_tf == pytest.approx(expected, abs=1e-9)
    nominal = simulate(_scenario(), check=False).metrics["segments"][0]["e_tf_norm"]
    assert abs(nominal - expected) > 1e-8  # far beyond the tolerance: the variant was applied


def test_mass_scale_is_in_the_plants_defaults_and_leaves_the_payload_alone():
    """M(q) of the default context scales with mass_scale (links and rotors alike); the
    payload's share of M does not."""
    q = np.radians(_scenario().robot.initial_q_deg)
    nominal = _mass_matrix(make_plant(_scenario()), q)
    heavy = _mass_matrix(make_plant(_scenario(mass_scale=1.5)), q)
    np.testing.assert_allclose(heavy, 1.5 * nominal, rtol=1e-12, atol=1e-15)
    payload = _mass_matrix(make_plant(_scenario(payload_kg=0.5)), q) - nominal
    heavy_payload = _mass_matrix(make_plant(_scenario(mass_scale=1.5, payload_kg=0.5)), q) - heavy
    np.testing.assert_allclose(heavy_payload, payload, rtol=1e-9, atol=1e-15)
    plant = make_plant(_scenario(mass_scale=1.5))
    context = plant.CreateDefaultContext()
    for index in plant.GetJointActuatorIndices():
        actuator = plant.get_joint_actuator(index)
        assert actuator.rotor_inertia(context) == pytest.approx(1.5 * 1.2e-6, rel=1e-12)


def test_scaling_keeps_the_models_kinematics_and_limits():
    nominal, heavy = make_plant(_scenario()), make_plant(_scenario(mass_scale=0.7))
    for name in ("GetPositionLowerLimits", "GetPositionUpperLimits", "GetVelocityUpperLimits",
                 "GetEffortUpperLimits", "MakeActuationMatrix"):
        np.testing.assert_array_equal(getattr(heavy, name)(), getattr(nominal, name)())
    q = np.radians([10.0, 30.0, 50.0])
    poses = []
    for plant in (nominal, heavy):
        context = plant.CreateDefaultContext()
        plant.SetPositions(context, q)
        poses.append(plant.GetFrameByName("tool").CalcPoseInWorld(context).GetAsMatrix4())
    np.testing.assert_array_equal(poses[0], poses[1])


def test_a_joint_the_scaled_copy_cannot_make_is_one_line_naming_the_field(tmp_path):
    model = tmp_path / "ball.urdf"
    model.write_text(
        '<?xml version="1.0"?><robot name="ball" xmlns:drake="http://drake.mit.edu"><link name="base"/>'
        '<link name="arm"><inertial><mass value="1"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>'
        '<link name="tool"/>'
        '<joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>'
        '<drake:joint name="j" type="ball"><parent link="base"/><child link="arm"/></drake:joint>'
        '<joint name="t" type="fixed"><parent link="arm"/><child link="tool"/></joint></robot>')
    scenario = _scenario(mass_scale=1.5)
    scenario.robot.model = str(model)
    with pytest.raises(ScenarioError, match=r"^plant\.mass_scale: the model's joint 'j' is a "):
        make_plant(scenario)
