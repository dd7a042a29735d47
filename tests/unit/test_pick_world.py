"""The pick-and-place world (issue 20): the arm's ports carry only the arm, the gripper's
fingertip centre is the arm's ``tool`` frame, a part's pose output is its simulated body pose,
the gripper driver closes at its speed, and bad settings name their field.  The 2 s hold and
belt-following runs are in tests/e2e/test_pick_world.py."""

from __future__ import annotations

import re

import numpy as np
import pytest
from pydrake.common.yaml import yaml_load_typed
from pydrake.systems.analysis import Simulator

from ptint_drake.simulation.validation import ScenarioError
from ptint_drake.systems.hand.gripper import GripperDriver
from ptint_drake.worlds.pick.config import BeltConfig, PartConfig, PickWorldConfig, SlotConfig, TrayConfig
from ptint_drake.worlds.pick.station import MakePickStation


def _world(**changes) -> PickWorldConfig:
    config = PickWorldConfig(belts=[BeltConfig()], parts=[PartConfig(), PartConfig(name="p2", offset=-0.1)],
                             tray=TrayConfig(slots=[SlotConfig(offset=[0.05, 0.0], yaw_deg=30.0)]))
    for key, value in changes.items():
        setattr(config, key, value)
    return config


@pytest.fixture(scope="module")
def station():
    return MakePickStation(_world())


def test_arm_ports_carry_only_the_arm(station):
    d, plant = station.diagram, station.plant
    assert plant.num_positions() > 5 + 2  # fingers, belt and free parts are in the plant …
    assert d.GetInputPort("actuation").size() == 5  # … but not in the arm's ports
    assert d.GetOutputPort("state").size() == 10
    context = d.CreateDefaultContext()
    q = d.GetOutputPort("state").Eval(context)
    np.testing.assert_allclose(q[:5], np.radians([22.5, 45.0, 30.0, 15.0, 0.0]))
    assert d.GetOutputPort("gripper_state").size() == 4 and d.GetOutputPort("grip_force").size() == 2


def test_fingertip_centre_is_the_tool_frame(station):
    plant = station.plant
    context = plant.CreateDefaultContext()
    tool = plant.GetFrameByName("tool", station.arm)
    tip = plant.GetFrameByName("fingertip_center", station.gripper)
    X = tool.CalcPose(context, tip)
    np.testing.assert_allclose(X.GetAsMatrix4(), np.eye(4), atol=1e-12)
    # the pads' inner faces sit symmetric about the tool origin, along the tool's x axis
    for name, side in (("left_finger", -1.0), ("right_finger", 1.0)):
        p = plant.GetBodyByName(name, station.gripper).body_frame().CalcPose(context, tool).translation()
        np.testing.assert_allclose(p, [side * 0.03, 0.0, 0.0], atol=1e-12)  # initial opening 60 mm


def test_part_pose_output_is_the_plant_body_pose(station):
    d, plant = station.diagram, station.plant
    context = d.CreateDefaultContext()
    pc = plant.GetMyContextFromRoot(context)
    station.start_running(pc)
    d.GetInputPort("actuation").FixValue(context, np.zeros(5))
    d.GetInputPort("gripper_command").FixValue(context, [0.06])
    Simulator(d, context).AdvanceTo(0.05)
    accelerations = plant.get_body_spatial_accelerations_output_port().Eval(pc)
    for k, body in enumerate(station.parts):
        X = plant.EvalBodyPoseInWorld(pc, body)
        V = plant.EvalBodySpatialVelocityInWorld(pc, body)
        A = accelerations[int(body.index())]
        assert np.any(A.get_coeffs() != 0.0)  # the parts ride the belts: contact, a real test
        pose = d.GetOutputPort(f"part_{k}_pose").Eval(context)
        rotation = d.GetOutputPort(f"part_{k}_rotation").Eval(context)
        # bit for bit the plant's body outputs (read from the free bodies' q, v and v̇)
        np.testing.assert_array_equal(pose, np.r_[X.translation(), V.translational(), A.translational()])
        np.testing.assert_array_equal(rotation, np.r_[X.rotation().matrix().ravel(), V.rotational(),
                                                      A.rotational()])
    assert d.GetOutputPort("part_1_pose").Eval(context)[1] == pytest.approx(-0.1 + 0.005, abs=5e-4)


def test_gripper_driver_closes_at_its_speed_and_past_the_centre():
    driver = GripperDriver(stroke=0.06, speed=0.05, max_force=30.0, kp=20000.0, initial_opening=0.06)
    context = driver.CreateDefaultContext()
    driver.get_input_port(0).FixValue(context, [0.0])
    driver.GetInputPort("finger_state").FixValue(context, [0.014, 0.014, 0.0, 0.0])  # stalled on a part
    simulator = Simulator(driver, context)
    simulator.AdvanceTo(0.1)
    ref = driver.GetOutputPort("desired_state").Eval(context)
    np.testing.assert_allclose(ref, [0.03 - 0.005, 0.03 - 0.005, -0.05, -0.05], atol=1e-9)
    simulator.AdvanceTo(1.0)
    np.testing.assert_allclose(driver.GetOutputPort("desired_state").Eval(context),
                               [-1.5 * 30.0 / 20000.0] * 2 + [0.0, 0.0], atol=1e-12)
    # opening again: the reference starts from the stalled fingers, not from deep behind them
    driver.get_input_port(0).FixValue(context, [0.04])
    simulator.AdvanceTo(1.001)
    np.testing.assert_allclose(driver.GetOutputPort("desired_state").Eval(context)[:2], [0.014 + 5e-5] * 2,
                               atol=1e-9)


def test_config_loads_from_yaml():
    text = """
contact_approximation: similar
belts: [{name: b1, speed: 0.12}]
parts: [{name: cyl, belt: b1, shape: cylinder, size: [0.03, 0.04], mass: 0.2, friction: 0.6}]
tray: {slots: [{offset: [0.05, 0.0], yaw_deg: 30}]}
"""
    config = yaml_load_typed(schema=PickWorldConfig, data=text)
    assert config.parts[0].shape == "cylinder" and config.belts[0].speed == 0.12
    assert config.tray.slots[0].yaw_deg == 30.0
    station = MakePickStation(config)
    assert station.slots[0].name() == "slot_0"


@pytest.mark.parametrize("changes, field", [
    ({"parts": [PartConfig(offset=0.7)]}, "pick.parts[0].offset"),
    ({"parts": [PartConfig(size=[0.07, 0.03, 0.03])]}, "pick.parts[0].size"),
    ({"parts": [PartConfig(belt="nope")]}, "pick.parts[0].belt"),
    ({"contact_approximation": "fast"}, "pick.contact_approximation"),
    ({"belts": [BeltConfig(direction=[0.0, 0.6, 0.8])]}, "pick.belts[0].direction"),
    ({"initial_q_deg": [0.0, 0.0, 0.0]}, "pick.initial_q_deg"),
])
def test_bad_settings_name_their_field(changes, field):
    config = _world(**changes)
    with pytest.raises(ScenarioError, match="^" + re.escape(field)):
        MakePickStation(config)
