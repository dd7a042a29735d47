"""``GripperDriver`` at rest on its goal: the update skips the finger read and the write (a CPU
saving of the harsh line study, issue 44) and must leave exactly what the full rule gives."""

import numpy as np
from pydrake.systems.analysis import Simulator

from ptint_drake.systems.hand.gripper import GripperDriver


def _rule(q, goal, fingers, step, period):
    """The driver's rule (its module docstring), written out here for one update."""
    out = []
    for i in (0, 1):
        qi = max(q[i], fingers[i]) if goal > q[i] else q[i]
        out.append((qi + min(max(goal - qi, -step), step), min(max(goal - qi, -step), step) / period))
    return [out[0][0], out[1][0], out[0][1], out[1][1]]


def test_driver_at_rest_matches_the_full_rule_bit_for_bit():
    driver = GripperDriver(stroke=0.06, speed=0.05, max_force=30.0, kp=20000.0, initial_opening=0.06)
    context = driver.CreateDefaultContext()
    simulator = Simulator(driver, context)
    fingers = driver.GetInputPort("finger_state")
    for t, command, held in ((1.0, 0.0, 0.014), (2.0, 0.04, 0.014), (3.0, 0.04, 0.03), (4.0, 0.0, 0.0)):
        driver.get_input_port(0).FixValue(context, [command])
        fingers.FixValue(context, [held, held, 0.0, 0.0])
        simulator.AdvanceTo(t)
        ref = driver.GetOutputPort("desired_state").Eval(context).copy()
        goal = driver.goal(command)
        assert ref[0] == goal and ref[1] == goal and ref[2] == 0.0 and ref[3] == 0.0  # at rest: the shortcut
        # fingers anywhere (above the reference too: the stall rule's case) change nothing at rest
        fingers.FixValue(context, [0.025, 0.02, 0.01, -0.01])
        simulator.AdvanceTo(t + 0.003)
        after = driver.GetOutputPort("desired_state").Eval(context)
        np.testing.assert_array_equal(after, _rule(ref, goal, [0.025, 0.02], 0.05 * 0.001, 0.001))
        np.testing.assert_array_equal(after, ref)
