"""The catch world's rendered ball camera (issue 46, ``worlds/catch/ball_camera.py``): in the
station's own depth frames (VTK, the D415-style noise) the ball is found where it is, in front of
the arm or far out at its launch, and nothing is found when only the arm is in view."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.math import RigidTransform

from ptint_drake.simulation.scenario import LoadedScenario
from ptint_drake.worlds.catch.ball import BALL_DIAMETER
from ptint_drake.worlds.catch.ball_camera import find_ball
from ptint_drake.worlds.catch.run import CatchRun


@pytest.fixture(scope="module")
def station():
    run = CatchRun(LoadedScenario.load("catch_toss_iiwa14_rgbd").scenario)
    context = run.diagram.CreateDefaultContext()
    return run, context


def _frame(station, ball_at, t: float = 0.0) -> tuple:
    """The ball placed at ``ball_at`` (world), the camera's noisy depth frame at ``t``, and what
    ``find_ball`` makes of it."""
    run, context = station
    st = run.station
    context.SetTime(t)
    st.plant.SetFreeBodyPose(st.plant.GetMyMutableContextFromRoot(context), st.ball, RigidTransform(ball_at))
    camera = st.camera
    image = camera.get_depth_image_input_port().Eval(camera.GetMyContextFromRoot(context))
    return find_ball(np.asarray(image.data)[:, :, 0], camera.info, camera.X_WC, BALL_DIAMETER / 2)


@pytest.mark.parametrize("where", [[0.85, 0.05, 0.75], [1.7, -0.4, 1.1], [1.2, 0.3, 1.6]])
def test_the_ball_is_found_where_it_is(station, where):
    found = _frame(station, np.array(where), t=1.0 / 60.0)
    assert found is not None
    assert np.linalg.norm(found - where) < 0.006  # m: 2.1-2.75 m away, with 6-11 mm of depth noise a pixel


def test_the_arm_alone_is_not_a_ball(station):
    for k in range(3):  # three noise draws
        assert _frame(station, np.array([0.0, 0.0, -10.0]), t=k / 60.0) is None
