"""The compiled task error (systems/task/error.py, orientation.py) against the equations written here
with numpy and Drake's quaternion (the earlier Python implementation), to 1e-12; the fused
pose kernel on the chain against the same law on the plant's kinematics."""

import math

import numpy as np
import pytest
from pydrake.common.eigen_geometry import Quaternion
from pydrake.math import RotationMatrix

from ptint_drake.controllers.ptsmc.gains import ControllerGains
from ptint_drake.controllers.ptsmc.interceptor import InterceptorLaw
from ptint_drake.robot import rvm1
from ptint_drake.robot.plant import parse_model
from ptint_drake.systems.task.error import task_error
from ptint_drake.systems.task.orientation import OrientedTarget, SpinningOrientation, rpy_matrix
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import SinusoidTarget


def _log(Re):
    """log(Re)^∨ through Drake's unit quaternion (w ≥ 0): 2 atan2(|v|, w) v/|v|."""
    q = RotationMatrix(Re).ToQuaternion()
    w, v = q.w(), np.array([q.x(), q.y(), q.z()])
    w, v = (-w, -v) if w < 0 else (w, v)
    n = np.linalg.norm(v)
    return 2.0 * v / w if n < 1e-12 else 2.0 * math.atan2(n, w) / n * v


def _top_down(rot_r, R):
    """[R_r, ω_r, ω̇_r] of the top-down grasp: ψ = atan2(a_y, a_x) of the object's x axis a on the
    π-branch nearest the tool's yaw, ψ̇ and ψ̈ from ȧ = ω × a, ä = ω̇ × a + ω × ȧ."""
    Ro, w, wd = np.reshape(rot_r[:9], (3, 3)), rot_r[9:12], rot_r[12:15]
    a = Ro[:, 0]
    ad = np.cross(w, a)
    add = np.cross(wd, a) + np.cross(w, ad)
    psi = math.atan2(a[1], a[0])
    psi += math.pi * round((math.atan2(R[1, 0], R[0, 0]) - psi) / math.pi)
    h = a[0] ** 2 + a[1] ** 2
    num = a[0] * ad[1] - a[1] * ad[0]
    psi_dd = ((a[0] * add[1] - a[1] * add[0]) * h - 2.0 * num * (a[0] * ad[0] + a[1] * ad[1])) / h**2
    Rr = np.array([[math.cos(psi), math.sin(psi), 0], [math.sin(psi), -math.cos(psi), 0], [0, 0, -1.0]])
    return np.r_[Rr.ravel(), 0, 0, num / h, 0, 0, psi_dd]


def _reference(task, c, x, xdot, x_r, xdot_r, R, omega, rot_r):
    e, edot = x - x_r, xdot - xdot_r
    if task == "position":
        return e, edot
    ref = _top_down(rot_r, R) if task == "top_down" else rot_r
    Re = R @ np.reshape(ref[:9], (3, 3)).T
    return np.r_[e, c * _log(Re)], np.r_[edot, c * (omega - Re @ ref[9:12])]


def _rotation(rng):
    q = rng.normal(size=4)
    return RotationMatrix(Quaternion(q / np.linalg.norm(q))).matrix()


@pytest.mark.parametrize("task", ["position", "pose", "top_down"])
def test_compiled_task_error_equals_the_equations(task):
    rng = np.random.default_rng(len(task))
    for k in range(300):
        x, xdot, x_r, xdot_r, omega, w_r, wd_r = rng.normal(size=(7, 3))
        R, R_r = _rotation(rng), _rotation(rng)
        if k % 50 == 0:  # a tiny error rotation: the small-angle branch of the log
            R = RotationMatrix(Quaternion(np.r_[1.0, 1e-14 * rng.normal(size=3)])).matrix() @ R_r
        rot_r = np.r_[R_r.ravel(), w_r, wd_r]
        c = rng.uniform(0.05, 0.5)
        e, edot = task_error(task, c, x, xdot, x_r, xdot_r, R, omega, rot_r)
        e_ref, edot_ref = _reference(task, c, x, xdot, x_r, xdot_r, R, omega, rot_r)
        np.testing.assert_allclose(e, e_ref, rtol=0, atol=1e-12)
        np.testing.assert_allclose(edot, edot_ref, rtol=0, atol=1e-12)


def test_spinning_orientation_is_exp_of_omega_t_times_R0():
    spin = SpinningOrientation([150.0, 50.0, 180.0], [10.0, -20.0, 30.0])
    w = np.radians([10.0, -20.0, 30.0])
    for t in (0.0, 0.3, 2.7):
        angle = np.linalg.norm(w) * t
        E = np.eye(3) if angle == 0 else RotationMatrix(Quaternion(np.r_[math.cos(angle / 2), math.sin(
            angle / 2) * w / np.linalg.norm(w)])).matrix()
        np.testing.assert_allclose(spin.values(t), np.r_[(E @ rpy_matrix([150.0, 50.0, 180.0])).ravel(), w,
                                                          0, 0, 0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("task", ["pose", "top_down"])
def test_pose_kernel_on_the_chain_equals_the_law_on_the_plants_kinematics(task):
    """The simulation's kernel (``pose_output``: compiled chain, compiled target and orientation),
    ``pose_row`` with Python-evaluated targets and ``task_row`` on Drake's kinematics give the
    same row (1e-12); its e, ė are ``task_error`` of the row's own x, ẋ, R, ω and targets."""
    model = "rvm1_6dof" if task == "pose" else "rvm1_5dof"
    plant = parse_model(model)
    plant.Finalize()
    target = OrientedTarget(SinusoidTarget([0.24, 0, 0.3], [0.1, 0.1, 0.1], 1.5, [0, 1.57, 0]),
                            SpinningOrientation([150.0, 50.0, 180.0], [0.0, -20.0, 30.0]))
    law = InterceptorLaw(plant=plant, frame=plant.GetFrameByName(rvm1.END_EFFECTOR),
                         schedule=Schedule([Segment(0.0, 1.5, 0.75)]), gains=ControllerGains(task=task),
                         targets=[target])
    assert law._chain is not None and law._rotations is not None
    layout, nv = law.layout, plant.num_velocities()
    rng = np.random.default_rng(nv)
    for t in (0.4, 1.7):
        qv, sigma = rng.normal(scale=0.5, size=2 * nv), rng.normal(scale=0.01, size=6)
        captured = np.r_[0.0, rng.normal(scale=0.1, size=6), np.zeros(6)]
        fast = law.row(t, qv, sigma, captured, None)
        rot = np.array(target.rotation_values(t))
        law._kernel, kernel = None, law._kernel  # the unpacked paths
        slow = law.row(t, qv, sigma, captured, target.evaluate(t), rot)
        law._chain, chain = None, law._chain
        plant_row = law.row(t, qv, sigma, captured, target.evaluate(t), rot)
        law._chain, law._kernel = chain, kernel
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-12)
        np.testing.assert_allclose(fast, plant_row, rtol=0, atol=1e-12)
        part = {name: fast[s] for name, s in layout.items()}
        e, edot = task_error(task, 0.1, part["x"], part["xdot"], part["x_r"], part["xdot_r"],
                             part["R"], part["omega"], part["target_rotation"])
        np.testing.assert_array_equal(part["e"], e)
        np.testing.assert_array_equal(part["edot"], edot)
