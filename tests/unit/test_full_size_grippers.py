"""Issue 45: the real-size grippers (schunk_wsg_50_110_full, robotiq_2f_85_full, panda_hand) —
generated files current, datasheet masses and strokes, the flange on the arm's flange when the
fingertip centre is welded to the arm's ``<gripper>_tip`` frame, and the mount check."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.pick import GripperConfig
from ptint_drake.robot.rvm1 import model_path
from ptint_drake.systems.hand.datasheets import check_mount, payload_warnings
from ptint_drake.worlds.pick.scene import AddGripper, gripper_stroke

ROOT = Path(__file__).resolve().parents[2]
# typed in from the datasheets cited in models/README.md ("Real-size grippers"), independently of
# grippers.FULL_SIZE: total mass (kg), stroke (m), fingertip centre beyond the flange (m), yaw (deg)
PUBLISHED = {"schunk_wsg_50_110_full": (1.2, 0.110, 0.0725 + 0.035, 0.0),
             "robotiq_2f_85_full": (0.925, 0.085, 0.150, 0.0),
             "panda_hand": (0.73, 0.080, 0.1034, -45.0)}
ARMS = ("iiwa14", "panda", "ur5e")


def test_generated_files_are_current():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "gripper_models.py"), "--check"],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout + out.stderr


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_mass_stroke_and_tip_match_the_datasheet(name):
    mass, stroke, depth, _ = PUBLISHED[name]
    plant = MultibodyPlant(0.0)
    (g,) = Parser(plant).AddModels(str(model_path(name).with_suffix(".sdf")))
    plant.Finalize()
    total = sum(plant.get_body(b).default_mass() for b in plant.GetBodyIndices(g))
    assert total == pytest.approx(mass, abs=1e-9)
    assert gripper_stroke(plant, g) == pytest.approx(stroke, abs=1e-12)
    context = plant.CreateDefaultContext()
    X = plant.GetFrameByName("fingertip_center", g).CalcPose(context, plant.GetBodyByName("gripper_base", g)
                                                             .body_frame())
    np.testing.assert_allclose(X.translation(), [0, 0, depth], atol=1e-9)
    for b in plant.GetBodyIndices(g):
        assert plant.get_body(b).default_spatial_inertia().IsPhysicallyValid()


@pytest.mark.parametrize("arm", ARMS)
@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_welded_at_its_tip_frame_the_flange_sits_on_the_arms_flange(arm, name):
    """fingertip_center welded to ``<name>_tip``: the gripper's flange (gripper_base's origin) is the
    arm's ``tool`` (the flange) turned by the datasheet's yaw, at every configuration."""
    plant = MultibodyPlant(0.001)
    (a,) = Parser(plant, "arm").AddModels(str(model_path(arm)))
    g = AddGripper(plant, plant.GetFrameByName(f"{name}_tip", a), GripperConfig(model=name))
    plant.Finalize()
    context = plant.CreateDefaultContext()
    rng = np.random.default_rng(1)
    q = plant.GetPositions(context, a)
    plant.SetPositions(context, a, rng.uniform(-1.0, 1.0, q.size))
    X_tool = plant.GetFrameByName("tool", a).CalcPoseInWorld(context)
    X_base = plant.GetBodyByName("gripper_base", g).EvalPoseInWorld(context)
    expected = X_tool.multiply(RigidTransform(RotationMatrix.MakeZRotation(np.radians(PUBLISHED[name][3]))))
    assert X_base.IsNearlyEqualTo(expected, 1e-9)


def test_mount_check_names_the_frame_in_one_line():
    frames = {"panda_hand_tip", "schunk_wsg_50_110_full_tip", "robotiq_2f_85_full_tip", "tool"}
    with pytest.raises(ScenarioError, match="use the frame 'panda_hand_tip'") as err:
        check_mount("panda_hand", "tool", frames.__contains__)
    assert "0.1034 m" in str(err.value) and "\n" not in str(err.value)
    with pytest.raises(ScenarioError, match="fingertip centre of panda_hand"):
        check_mount("robotiq_2f_85_full", "panda_hand_tip", frames.__contains__)
    check_mount("panda_hand", "panda_hand_tip", frames.__contains__)
    check_mount("panda_hand", "hand", {"hand"}.__contains__)  # a user's arm without the frame
    check_mount("rvm1_gripper", "tool", frames.__contains__)


def test_payload_warning_names_both_masses_per_arm():
    class Part:
        name, mass = "heavy", 2.5
    (w,) = payload_warnings("panda", "panda_hand", 0.73, [Part()])
    assert "0.73 kg" in w and "2.50 kg" in w and "3 kg" in w and "panda" in w
    assert payload_warnings("iiwa14", "schunk_wsg_50_110_full", 1.2, [Part()]) == []
    Part.mass = 4.2  # 0.925 + 4.2 > 5 kg
    assert len(payload_warnings("ur5e", "robotiq_2f_85_full", 0.925, [Part()])) == 1
