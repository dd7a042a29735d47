"""The bundled 6-joint arm ``rvm1_6dof`` (issue 19): the RV-M1's first three links exactly, a
spherical roll-pitch-roll wrist, a ``tool`` frame 0.12 m past the wrist point, every joint with
finite limits, effort and damping (models/README.md)."""

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable

from ptint_drake.robot.rvm1 import FINGERTIP_OFFSET, bundled_models, model_path, paper_fk, q_from_theta

JOINTS = ["waist", "shoulder", "elbow", "forearm_roll", "wrist_pitch", "wrist_roll"]


@pytest.fixture(scope="module")
def arm():
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path("rvm1_6dof")))
    plant.Finalize()
    return plant


def test_six_revolute_joints_with_finite_limits_effort_and_damping(arm):
    assert "rvm1_6dof" in bundled_models()
    joints = [arm.get_joint(i) for i in arm.GetJointIndices() if arm.get_joint(i).num_velocities()]
    assert [j.name() for j in joints] == JOINTS
    assert all(j.type_name() == "revolute" and j.default_damping() > 0 for j in joints)
    limits = np.r_[arm.GetPositionLowerLimits(), arm.GetPositionUpperLimits()]
    assert np.all(np.isfinite(limits))
    effort = arm.GetEffortUpperLimits()
    assert effort.shape == (6,) and np.all(np.isfinite(effort)) and np.all(effort > 0)
    assert arm.num_actuators() == 6


def test_wrist_point_follows_the_paper_and_the_tool_is_on_a_spherical_wrist(arm):
    """The wrist point (all three wrist axes through it) is the paper's gripper point (eq. 26)
    for any wrist angles, and ``tool`` stays FINGERTIP_OFFSET from it."""
    ctx = arm.CreateDefaultContext()
    rng = np.random.default_rng(6)
    wrist, tool = arm.GetFrameByName("wrist"), arm.GetFrameByName("tool")
    for theta in rng.uniform(-1.5, 1.5, (10, 6)):
        arm.SetPositions(ctx, theta)
        point = wrist.CalcPoseInWorld(ctx).translation()
        np.testing.assert_allclose(point, paper_fk(q_from_theta(theta[:3])), atol=1e-12)
        assert abs(np.linalg.norm(tool.CalcPoseInWorld(ctx).translation() - point) - FINGERTIP_OFFSET) < 1e-12


def test_jacobian_is_full_rank_off_the_wrist_singularity(arm):
    """[J_v; J_ω] of ``tool`` is invertible at curve_pose's start (pitch −45°), singular at pitch 0."""
    ctx = arm.CreateDefaultContext()
    tool, world = arm.GetFrameByName("tool"), arm.world_frame()

    def smallest_singular_value(q_deg):
        arm.SetPositions(ctx, np.radians(q_deg))
        J = arm.CalcJacobianSpatialVelocity(ctx, JacobianWrtVariable.kV, tool, np.zeros(3), world, world)
        return np.linalg.svd(J, compute_uv=False)[-1]

    assert smallest_singular_value([22.5, 45.0, 30.0, 0.0, -45.0, 0.0]) > 0.02
    assert smallest_singular_value([22.5, 45.0, 30.0, 0.0, 0.0, 0.0]) < 1e-12
