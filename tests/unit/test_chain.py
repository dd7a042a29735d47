"""The compiled kinematic chain (systems/task/chain.py) against Drake's kinematics, to 1e-12."""

import numpy as np
import pytest
from heavy_arm import heavy_arm_urdf
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from ptint_drake.robot import rvm1
from ptint_drake.robot.plant import parse_model
from ptint_drake.systems.task.chain import KinematicChain
from ptint_drake.systems.task.kinematics import FrameKinematics

# turned joint frames (rpy), an off-axis revolute axis, a prismatic joint and a turned tool
TWISTED = """<?xml version="1.0"?><robot name="twisted">
  <link name="base"/><joint name="weld" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0.1 -0.2 0.05" rpy="0.1 0.2 0.3"/></joint>
  <link name="a"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="b"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="c"><inertial><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.3" rpy="0.4 0 -0.2"/><axis xyz="0.6 0 0.8"/>
    <limit effort="10" lower="-3" upper="3" velocity="5"/></joint>
  <joint name="j2" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0.1 0" rpy="0 0.5 0"/><axis xyz="1 0 0"/>
    <limit effort="10" lower="-1" upper="1" velocity="5"/></joint>
  <joint name="j3" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0 0 0.25" rpy="-0.3 0.1 0.7"/><axis xyz="0 1 0"/>
    <limit effort="10" lower="-3" upper="3" velocity="5"/></joint>
  <link name="tool"/><joint name="tool_fix" type="fixed"><parent link="c"/><child link="tool"/>
    <origin xyz="0.15 0.02 -0.03" rpy="0.2 -0.4 1.0"/></joint>
</robot>"""


def _plant(text: str) -> MultibodyPlant:
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(text, "urdf")
    plant.Finalize()
    return plant


def _bundled(model: str) -> MultibodyPlant:
    plant = parse_model(model)
    plant.Finalize()
    return plant


@pytest.mark.parametrize("make, frame", [
    (lambda: _bundled("rvm1"), rvm1.END_EFFECTOR), (lambda: _bundled("rvm1_5dof"), rvm1.END_EFFECTOR),
    (lambda: _bundled("rvm1_6dof"), rvm1.END_EFFECTOR),
    (lambda: _plant(heavy_arm_urdf()), "tool"),
    (lambda: _plant(TWISTED), "tool")])
def test_chain_equals_drakes_kinematics(make, frame):
    """x, R, J_v, J_ω at random q equal the plant's (CalcPoseInWorld, CalcJacobianSpatialVelocity)."""
    plant = make()
    F = plant.GetFrameByName(frame)
    chain = KinematicChain.of(plant, F)
    assert chain is not None
    context = plant.CreateDefaultContext()
    rng = np.random.default_rng(plant.num_positions())
    world = plant.world_frame()
    for _ in range(10):
        q = rng.uniform(-2.5, 2.5, plant.num_positions())
        plant.SetPositions(context, q)
        X = F.CalcPoseInWorld(context)
        Js = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, F, np.zeros(3), world, world)
        x, R, J_v, J_w = chain.evaluate(q)
        np.testing.assert_allclose(x, X.translation(), rtol=0, atol=1e-12)
        np.testing.assert_allclose(R, X.rotation().matrix(), rtol=0, atol=1e-12)
        np.testing.assert_allclose(J_v, Js[3:], rtol=0, atol=1e-12)
        np.testing.assert_allclose(J_w, Js[:3], rtol=0, atol=1e-12)


def test_anything_else_falls_back_to_the_plant():
    """A floating body is no serial chain: FrameKinematics then asks the plant (same values)."""
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModelsFromString(TWISTED.replace(
        '<joint name="weld" type="fixed"><parent link="world"/><child link="base"/>\n'
        '    <origin xyz="0.1 -0.2 0.05" rpy="0.1 0.2 0.3"/></joint>', ""), "urdf")
    plant.Finalize()
    kin = FrameKinematics(plant, plant.GetFrameByName("tool"))
    assert kin.chain is None
    q = plant.GetDefaultPositions()
    x, xdot, J = kin.compute(q, np.zeros(plant.num_velocities()))
    assert J.shape == (3, plant.num_velocities()) and np.all(xdot == 0.0)
