"""The Mitsubishi RV-M1 (first three joints): paper kinematics and the bundled model.

Paper convention q (SPEC section 3, paper eqs. 26-27), h1 = 0.3, l1 = 0.25,
l2 = 0.16 m.  The bundled model ``models/rvm1.urdf`` uses serial-chain angles θ:

    θ1 = q1,  θ2 = q2,  θ3 = −(2 q2 + q3)   ⇔   q3 = −(2 θ2 + θ3)
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

import numpy as np

H1, L1, L2 = 0.3, 0.25, 0.16
# The paper's start pose of both tasks, gripper at (0.2016, 0.0835, 0.3222) m.
START_Q_DEG = (22.5, 45.0, -120.0)
START_THETA_DEG = (22.5, 45.0, 30.0)
END_EFFECTOR = "tool"
# The 5-joint RV-M1 with its wrist (models/rvm1_5dof.urdf): frame ``tool`` is the centre between
# the fingertips, this far from the wrist-pitch axis along the hand (z = approach direction, x
# across the fingers); any later gripper model must put its fingertip centre there.
MODEL_5DOF = "rvm1_5dof"
FINGERTIP_OFFSET = 0.12  # m


def _models_dir() -> Path:
    """The bundled models: the source tree's models/ beside this package when there is one (a
    checkout, whatever else is installed), else ``ptint_drake.models`` (an installed package)."""
    source = Path(__file__).resolve().parents[2] / "models"  # (robot/ is one folder down)
    if (source / "rvm1.urdf").is_file():
        return source
    try:
        return Path(str(resources.files("ptint_drake.models")))
    except ModuleNotFoundError:
        return Path(__file__).resolve().parents[2] / "models"


def model_path(name: str = "rvm1") -> Path:
    """Path of a bundled model file (installed with the package as ptint_drake.models)."""
    return _models_dir() / f"{name}.urdf"


def bundled_models() -> list[str]:
    """Names of the robot models shipped in ``ptint_drake.models`` (URDF file stems)."""
    return sorted(p.name[:-5] for p in _models_dir().iterdir() if p.name.endswith(".urdf"))


def theta_from_q(q) -> np.ndarray:
    """Model angles θ from paper angles q (radians, last axis of length 3)."""
    q = np.asarray(q, dtype=float)
    return np.stack([q[..., 0], q[..., 1], -(2.0 * q[..., 1] + q[..., 2])], axis=-1)


def q_from_theta(theta) -> np.ndarray:
    """Paper angles q from model angles θ (radians); the inverse of ``theta_from_q``."""
    th = np.asarray(theta, dtype=float)
    return np.stack([th[..., 0], th[..., 1], -(2.0 * th[..., 1] + th[..., 2])], axis=-1)


def paper_fk(q) -> np.ndarray:
    """Gripper point [X, Y, Z] from paper angles q (paper eq. 26)."""
    q1, q2, q3 = np.asarray(q, dtype=float)
    r = L1 * np.sin(q2) + L2 * np.cos(q2 + q3)
    return np.array([np.cos(q1) * r, np.sin(q1) * r, H1 + L1 * np.cos(q2) + L2 * np.sin(q2 + q3)])


def paper_jacobian(q) -> np.ndarray:
    """∂x/∂q of ``paper_fk`` (paper eq. 27, with the restored signs of SPEC section 3)."""
    q1, q2, q3 = np.asarray(q, dtype=float)
    s1, c1 = np.sin(q1), np.cos(q1)
    s23, c23 = np.sin(q2 + q3), np.cos(q2 + q3)
    r = L1 * np.sin(q2) + L2 * c23
    a = L1 * np.cos(q2) - L2 * s23
    return np.array([
        [-s1 * r, c1 * a, -L2 * c1 * s23],
        [c1 * r, s1 * a, -L2 * s1 * s23],
        [0.0, -L1 * np.sin(q2) + L2 * c23, L2 * c23],
    ])
