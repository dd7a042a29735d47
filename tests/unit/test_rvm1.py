"""The bundled RV-M1 model against the paper's kinematics (SPEC section 3)."""

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.robot.rvm1 import (START_Q_DEG, START_THETA_DEG, model_path, paper_fk, paper_jacobian,
                                    q_from_theta, theta_from_q)
from ptint_drake.systems.task.kinematics import TaskSpaceKinematics


@pytest.fixture(scope="module")
def kinematics():
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path()))
    plant.Finalize()
    return TaskSpaceKinematics(plant, plant.GetFrameByName("tool"))


def test_start_pose():
    assert np.allclose(theta_from_q(np.radians(START_Q_DEG)), np.radians(START_THETA_DEG))
    assert np.allclose(paper_fk(np.radians(START_Q_DEG)), [0.2016, 0.0835, 0.3222], atol=1e-4)


def test_conversion_round_trip():
    rng = np.random.default_rng(1)
    q = rng.uniform(-np.pi, np.pi, (50, 3))
    np.testing.assert_allclose(q_from_theta(theta_from_q(q)), q, atol=1e-14)
    np.testing.assert_allclose(theta_from_q(q_from_theta(q)), q, atol=1e-14)


def test_plant_fk_and_jacobian_match_paper(kinematics):
    """x = f(q) and J of the plant (θ coordinates) equal the paper's eqs. 26-27 at random q."""
    rng = np.random.default_rng(7)
    dtheta_dq = np.array([[1, 0, 0], [0, 1, 0], [0, -2, -1]], dtype=float)
    for q in rng.uniform(-np.pi, np.pi, (100, 3)):
        theta = theta_from_q(q)
        v = rng.normal(size=3)
        out = kinematics.evaluate(theta, v)
        x, xdot, J = out[0:3], out[3:6], out[6:].reshape(3, 3)
        np.testing.assert_allclose(x, paper_fk(q), atol=1e-12)
        # chain rule: J_paper = J_θ dθ/dq
        np.testing.assert_allclose(J @ dtheta_dq, paper_jacobian(q), atol=1e-12)
        np.testing.assert_allclose(xdot, J @ v, atol=1e-12)


def test_paper_jacobian_is_derivative_of_fk():
    rng = np.random.default_rng(3)
    h = 1e-6
    for q in rng.uniform(-np.pi, np.pi, (20, 3)):
        num = np.column_stack([(paper_fk(q + h * e) - paper_fk(q - h * e)) / (2 * h) for e in np.eye(3)])
        np.testing.assert_allclose(paper_jacobian(q), num, atol=1e-8)


def test_model_is_packaged_with_documented_assumptions():
    path = model_path()
    assert path.is_file()
    readme = path.parent / "README.md"
    assert readme.is_file()
    text = readme.read_text()
    for word in ("mass", "damping", "effort", "rotor", "assumption"):
        assert word in text.lower()
