"""Issue 45, every world on each bundled industrial arm: a pose task per arm (``pose_ARM``)."""

import numpy as np
import pytest
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant

from conftest import assert_prescribed_time
from ptint_drake.rvm1 import model_path

ARMS = ("iiwa14", "panda", "ur5e")


def _inside_limits(arm: str, q: np.ndarray) -> bool:
    plant = MultibodyPlant(0.0)
    Parser(plant).AddModels(str(model_path(arm)))
    plant.Finalize()
    q = q if q.shape[-1] == plant.num_positions() else q.T
    return bool(np.all(q >= plant.GetPositionLowerLimits()) and np.all(q <= plant.GetPositionUpperLimits()))


@pytest.mark.parametrize("arm", ARMS)
def test_pose_meets_criteria(run, arm):
    """``pose_ARM``: the tool meets the tumbling object within 1 mm and 2° at tf, not before tf/2
    (in distance and in angle), holds it within 3 mm / 5°, and no joint leaves its range."""
    result = run(f"pose_{arm}")
    m = result.metrics
    assert m["status"] == "ok", m.get("reasons")
    assert_prescribed_time(m, f"pose_{arm}")
    seg = m["segments"][0]
    assert seg["e_tf_norm"] <= 1e-3 and seg["e_rot_tf_deg"] <= 2.0, (seg["e_tf_norm"], seg["e_rot_tf_deg"])
    assert seg["e0_norm"] > 0.04 and seg["e_rot0_deg"] > 30.0
    assert seg["e_half_norm"] >= 0.25 * seg["e0_norm"] and seg["e_rot_half_deg"] >= 0.25 * seg["e_rot0_deg"]
    assert seg["e_hold_max_norm"] <= 3e-3 and seg["e_rot_hold_max_deg"] <= 5.0
    assert _inside_limits(arm, np.asarray(result.series["q"]))
