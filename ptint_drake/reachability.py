"""Can the arm reach its targets?  Drake's InverseKinematics with the model's joint limits.

``check_reachable`` is the check before a run (a ScenarioError naming the
interception); ``inverse_kinematics`` is the one solve it and the torque estimate
(``run_warnings.torque_feasibility``) use.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.plant import MultibodyPlant
from pydrake.solvers import Solve

from ptint_drake.scenario import Scenario, ScenarioError

POSITION_TOLERANCE = 1e-3  # m, per axis
DOWN_TOLERANCE = np.radians(2.0)  # rad, of a top-down tool axis


def inverse_kinematics(plant: MultibodyPlant, frame, x: np.ndarray,
                       guess: np.ndarray, down: bool = False) -> Optional[np.ndarray]:
    """Joint positions within the model's limits that put ``frame``'s origin within
    ``POSITION_TOLERANCE`` of ``x`` (world), solved from ``guess``; None if none was found.
    ``down``: with the frame's z axis within ``DOWN_TOLERANCE`` of straight down (a top-down grasp)."""
    ik = InverseKinematics(plant, with_joint_limits=True)
    ik.AddPositionConstraint(frame, np.zeros(3), plant.world_frame(),
                             x - POSITION_TOLERANCE, x + POSITION_TOLERANCE)
    if down:
        ik.AddAngleBetweenVectorsConstraint(frame, [0.0, 0.0, 1.0], plant.world_frame(), [0.0, 0.0, -1.0],
                                            0.0, DOWN_TOLERANCE)
    ik.prog().SetInitialGuess(ik.q(), guess)
    result = Solve(ik.prog())
    return result.GetSolution(ik.q()) if result.is_success() else None


def check_reachable(plant: MultibodyPlant, scenario: Scenario, samples_per_hold: int = 4) -> None:
    """Every target must be reachable at its interception time and during its hold.

    Solved from the initial pose and then from the previous solution.  Raises
    ScenarioError naming the interception.
    """
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    schedule = scenario.schedule()
    targets = scenario.targets()
    guess = np.radians(scenario.robot.initial_q_deg)
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, scenario.duration)
        for t in np.linspace(seg.end, max(t_end, seg.end), samples_per_hold):
            x = targets[i].evaluate(t)[0:3]
            solution = inverse_kinematics(plant, frame, x, guess)
            if solution is None:
                raise ScenarioError(
                    f"interceptions[{i}].target: position {np.round(x, 4).tolist()} m at "
                    f"t = {t:.3f} s is outside the arm's workspace")
            guess = solution
