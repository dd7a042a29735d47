"""Session 53: the line on the Panda and the UR5e as a new user writes it (tests/line_panda.yaml,
tests/line_ur5e.yaml) places every part that entered, within 3 mm, touching nothing, with every
commanded torque within its limit and never a saturated step.  Before, each placed none: the line
planned every phase at the min-tf model's shortest tf from the arm's limits alone, which on these
arms is shorter than their model-free loop tracks (the Panda's lift ended 5.3 mm off and its carry
ran joint 2 into its limit; the UR5e's lift ended 11.6 mm off with joint 4 at 2.1 × its speed
limit).  Now a phase lasts at least ``phase_time.TRACKING`` time constants of the velocity loop
(docs/pick_place.md "On the other bundled arms")."""

from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.slow

TESTS = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("arm", ["panda", "ur5e"])
def test_a_line_on_a_heavier_arm_places_every_part_within_its_limits(run, arm):
    m = run(str(TESTS / f"line_{arm}.yaml")).metrics
    line = m["line"]
    assert line["entered"] >= 2
    assert line["placed"] == line["entered"], [p.get("reason") for p in line["parts"]]
    assert m["status"] == "ok" and m["warnings"] == []
    for pick in m["picks"]:
        assert pick["placed"] and not pick["collision"], pick
        assert pick["place_error_mm"] <= 3.0, pick
    assert m["saturated_fraction"] == 0.0
    assert np.all(np.array(m["torque_command_peak"]) <= np.array(m["effort_limits"]))
