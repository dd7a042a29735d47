"""Issue 45: the bundled iiwa14, Panda and UR5e models against their published tables.

The tables below are typed in from the sources cited in models/README.md, independently of
scripts/arm_models.py (which writes the URDFs): forward kinematics of frame ``tool`` against a
plain DH implementation, limits, masses, inertias and collision geometry.
"""

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph, MultibodyPlant
from pydrake.multibody.tree import RevoluteJoint
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.robot.rvm1 import bundled_models, model_path

ROOT = Path(__file__).resolve().parents[2]
D = math.pi / 180.0
H = math.pi / 2

# (a, d, alpha) per row.  iiwa: standard DH from KUKA's lengths 0.36 / 0.42 / 0.40 / 0.126 m;
# UR5e: UR's published standard DH; Panda: Franka's modified (Craig) DH, last row = the flange.
DH = {
    "iiwa14": ("standard", [(0, 0.36, -H), (0, 0, H), (0, 0.42, H), (0, 0, -H), (0, 0.40, -H), (0, 0, H),
                            (0, 0.126, 0)]),
    "panda": ("modified", [(0, 0.333, 0), (0, 0, -H), (0, 0.316, H), (0.0825, 0, H), (-0.0825, 0.384, -H),
                           (0, 0, H), (0.088, 0, H), (0, 0.107, 0)]),
    "ur5e": ("standard", [(0, 0.1625, H), (-0.425, 0, 0), (-0.3922, 0, 0), (0, 0.1333, H), (0, 0.0997, -H),
                          (0, 0.0996, 0)]),
}
LIMITS = {  # (lower rad, upper rad, velocity rad/s, effort N·m) per joint
    "iiwa14": [(-r * D, r * D, v * D, t) for r, v, t in zip((170, 120, 170, 120, 170, 120, 175),
                                                            (85, 85, 100, 75, 130, 135, 135),
                                                            (320, 320, 176, 176, 110, 40, 40))],
    "panda": list(zip((-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
                      (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
                      (2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61), (87, 87, 87, 87, 12, 12, 12))),
    "ur5e": [(-2 * math.pi, 2 * math.pi, math.pi, t) for t in (150, 150, 150, 28, 28, 28)],
}
DATASHEET_MASS = {"iiwa14": 29.9, "panda": 18.0, "ur5e": 20.6}
# masses published per moving link (Gaz et al. 2019 for the Panda, UR's DH page for the UR5e)
LINK_MASSES = {"panda": (4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522),
               "ur5e": (3.761, 8.058, 2.846, 1.37, 1.3, 0.365)}
ARMS = tuple(DH)


def dh_forward(name: str, q: np.ndarray) -> np.ndarray:
    """4 × 4 pose of the last DH frame (the flange) from the published table."""
    convention, rows = DH[name]
    T = np.eye(4)
    qs = list(q) + [0.0] * (len(rows) - len(q))
    for (a, d, alpha), theta in zip(rows, qs):
        ca, sa, ct, st = math.cos(alpha), math.sin(alpha), math.cos(theta), math.sin(theta)
        if convention == "standard":   # Rz(θ) Tz(d) Tx(a) Rx(α)
            A = np.array([[ct, -st * ca, st * sa, a * ct], [st, ct * ca, -ct * sa, a * st],
                          [0, sa, ca, d], [0, 0, 0, 1]])
        else:                          # Rx(α) Tx(a) Rz(θ) Tz(d)
            A = np.array([[ct, -st, 0, a], [st * ca, ct * ca, -sa, -d * sa],
                          [st * sa, ct * sa, ca, d * ca], [0, 0, 0, 1]])
        T = T @ A
    return T


def _plant(name: str, scene_graph: bool = False):
    if scene_graph:
        plant, graph = AddMultibodyPlantSceneGraph(DiagramBuilder(), 0.0)
    else:
        plant, graph = MultibodyPlant(0.0), None
    Parser(plant).AddModels(str(model_path(name)))
    plant.Finalize()
    return plant, graph


@pytest.mark.parametrize("name", ARMS)
def test_bundled(name):
    assert name in bundled_models()


@pytest.mark.parametrize("name", ARMS)
def test_tool_frame_matches_published_dh(name):
    """The plant's frame ``tool`` (position and orientation) equals the DH table's flange frame at
    100 random configurations inside the joint ranges."""
    plant, _ = _plant(name)
    context = plant.CreateDefaultContext()
    tool = plant.GetFrameByName("tool")
    low, high = plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits()
    rng = np.random.default_rng(45)
    for q in rng.uniform(low, high, (100, plant.num_positions())):
        plant.SetPositions(context, q)
        X = plant.CalcRelativeTransform(context, plant.world_frame(), tool)
        T = dh_forward(name, q)
        np.testing.assert_allclose(X.translation(), T[:3, 3], atol=1e-9)
        np.testing.assert_allclose(X.rotation().matrix(), T[:3, :3], atol=1e-9)


def test_the_dh_check_can_fail():
    """A wrong table (the UR5's CB-series d1 0.0892 instead of the UR5e's 0.1625) is told apart."""
    plant, _ = _plant("ur5e")
    context = plant.CreateDefaultContext()
    X = plant.CalcRelativeTransform(context, plant.world_frame(), plant.GetFrameByName("tool"))
    rows = list(DH["ur5e"][1])
    rows[0] = (0, 0.0892, H)
    saved = DH["ur5e"]
    try:
        DH["ur5e"] = ("standard", rows)
        assert np.linalg.norm(X.translation() - dh_forward("ur5e", np.zeros(6))[:3, 3]) > 0.05
    finally:
        DH["ur5e"] = saved


@pytest.mark.parametrize("name", ARMS)
def test_inertias_are_physically_valid(name):
    plant, _ = _plant(name)
    instance = plant.GetModelInstanceByName(name)
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        if body.name() == "tool":  # a frame: no mass of its own
            continue
        M = body.default_spatial_inertia()
        assert M.get_mass() > 0.0, body.name()
        assert M.IsPhysicallyValid(), body.name()
        # principal moments about the centre of mass obey the triangle inequality
        inertia = M.Shift(M.get_com()).CalcRotationalInertia().CopyToFullMatrix3()
        moments = np.sort(np.linalg.eigvalsh(inertia))
        assert moments[0] > 0.0, body.name()
        assert moments[0] + moments[1] >= moments[2] * (1 - 1e-9), body.name()


@pytest.mark.parametrize("name", ARMS)
def test_total_mass_matches_datasheet(name):
    plant, _ = _plant(name)
    instance = plant.GetModelInstanceByName(name)
    total = sum(plant.get_body(i).default_mass() for i in plant.GetBodyIndices(instance))
    assert abs(total - DATASHEET_MASS[name]) <= 0.05 * DATASHEET_MASS[name]
    if name in LINK_MASSES:  # the published per-link masses are used as they are
        masses = [plant.GetBodyByName(f"link{i}").default_mass()
                  for i in range(1, len(LINK_MASSES[name]) + 1)]
        np.testing.assert_allclose(masses, LINK_MASSES[name], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ARMS)
def test_limits_equal_cited_tables(name):
    plant, _ = _plant(name)
    table = np.array(LIMITS[name], dtype=float)
    assert plant.num_positions() == plant.num_actuators() == len(table)
    np.testing.assert_allclose(plant.GetPositionLowerLimits(), table[:, 0], atol=1e-12)
    np.testing.assert_allclose(plant.GetPositionUpperLimits(), table[:, 1], atol=1e-12)
    np.testing.assert_allclose(plant.GetVelocityUpperLimits(), table[:, 2], atol=1e-12)
    np.testing.assert_allclose(plant.GetVelocityLowerLimits(), -table[:, 2], atol=1e-12)
    efforts = [plant.get_joint_actuator(i).effort_limit() for i in plant.GetJointActuatorIndices()]
    np.testing.assert_allclose(efforts, table[:, 3], atol=1e-12)
    revolute = [plant.get_joint(i) for i in plant.GetJointIndices(plant.GetModelInstanceByName(name))
                if isinstance(plant.get_joint(i), RevoluteJoint)]
    assert len(revolute) == len(table)
    assert all(joint.default_damping() > 0.0 for joint in revolute)  # damping: an assumption, present


@pytest.mark.parametrize("name", ARMS)
def test_every_link_has_collision_geometry(name):
    plant, graph = _plant(name, scene_graph=True)
    instance = plant.GetModelInstanceByName(name)
    inspector = graph.model_inspector()
    for index in plant.GetBodyIndices(instance):
        body = plant.get_body(index)
        if body.name() == "tool":
            continue
        geometries = plant.GetCollisionGeometriesForBody(body)
        assert geometries, body.name()
        assert plant.GetVisualGeometriesForBody(body), body.name()
        for geometry in geometries:
            assert inspector.GetShape(geometry).__class__.__name__ in ("Cylinder", "Box", "Sphere")


def test_generated_files_are_current():
    """models/*.urdf are what scripts/arm_models.py writes from its cited tables."""
    result = subprocess.run([sys.executable, str(ROOT / "scripts" / "arm_models.py"), "--check"],
                            capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stdout + result.stderr


def test_null_space_term_at_a_singular_jacobian():
    """At q = 0 the iiwa stands straight up and its 3 × 7 position Jacobian has rank 1: the
    null-space term (controller.null_space_damping, built once at q = 0 when the diagram is
    made) is finite there and still leaves the tool point alone."""
    from pydrake.multibody.tree import JacobianWrtVariable  # noqa: PLC0415

    from ptint_drake.controllers.ptsmc.law import null_space_torque  # noqa: PLC0415

    plant, _ = _plant("iiwa14")
    context = plant.CreateDefaultContext()
    J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, plant.GetFrameByName("tool"),
                                                np.zeros(3), plant.world_frame(), plant.world_frame())
    assert np.linalg.matrix_rank(J) == 1  # every pitch axis moves the tool along x only
    rng = np.random.default_rng(1)
    tau = null_space_torque(J, np.zeros(7), rng.normal(size=7), rng.normal(size=7), 10.0, 2.0)
    assert np.all(np.isfinite(tau)) and np.linalg.norm(tau) > 0.0
    np.testing.assert_allclose(J @ tau, 0.0, atol=1e-9)


def test_limit_push_is_zero_inside_and_grows_into_the_band():
    from ptint_drake.controllers.ptsmc.law import limit_push  # noqa: PLC0415

    lower, upper = np.array([-1.0, -1.0, -np.inf]), np.array([1.0, 1.0, np.inf])
    push = limit_push(np.array([0.95, -0.85, 5.0]), lower, upper, 0.1)
    np.testing.assert_allclose(push, [0.05, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(limit_push(np.array([-0.97, 0.0, 0.0]), lower, upper, 0.1), [-0.07, 0, 0],
                               atol=1e-15)


def test_posture_task_pushes_a_joint_away_from_its_limit_in_the_null_space():
    """iiwa at rest, joint 4 one degree from its −120° limit, margin 10°: the posture task's torque
    moves joint 4 away from the limit (a positive torque) and leaves the tool point alone."""
    from pydrake.multibody.tree import JacobianWrtVariable  # noqa: PLC0415

    from ptint_drake.config.controller import ControllerGains  # noqa: PLC0415
    from ptint_drake.controllers.ptsmc.law import null_space_terms, null_space_torque  # noqa: PLC0415

    plant, _ = _plant("iiwa14")
    q = np.radians([0.0, 30.0, 0.0, -119.0, 0.0, 60.0, 0.0])
    gains = ControllerGains(null_space_damping=10.0, null_space_limit_margin_deg=10.0)
    D, rate, rest, limits = null_space_terms(gains, plant, posture=q)  # rest = here: no posture pull
    np.testing.assert_allclose(rest, q)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, q)
    J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, plant.GetFrameByName("tool"),
                                                np.zeros(3), plant.world_frame(), plant.world_frame())
    tau = null_space_torque(J, q, np.zeros(7), rest, D, rate, limits)
    assert tau[3] > 0.0
    np.testing.assert_allclose(J @ tau, 0.0, atol=1e-9)
    off = null_space_terms(ControllerGains(null_space_damping=10.0), plant, posture=q)
    assert off[3] is None and np.allclose(null_space_torque(J, q, np.zeros(7), rest, D, rate, off[3]), 0.0)
    # a rest posture given in the scenario replaces the start posture
    rest_given = null_space_terms(ControllerGains(null_space_damping=10.0, null_space_posture_deg=[0.0] * 7),
                                  plant, posture=q)[2]
    np.testing.assert_allclose(rest_given, np.zeros(7))
