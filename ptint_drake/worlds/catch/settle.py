"""The arm at rest before the throw (issue 46): a catch starts from the state the arm's
controller holds the start pose in, not from a controller that has yet to learn the arm's weight.

The model-free law carries the gravity load in its integral σ.  Started with σ = 0 the iiwa 14
sags under its own weight and is pulled back on the sensing segment's prescribed time: measured
on throw 0, the hand sagged 23 mm in 0.1 s and reached t_plan = 0.15 s with joint 2 at 93 % of
its speed limit, the worst possible start for a catch.  A real arm waiting for a throw is already
holding its pose.  So the catch world first simulates that wait once (``SETTLE_TF`` s of a
segment aimed at the start pose, then ``SETTLE_HOLD`` s of hold; the same diagram, the ball
parked away from the arm) and every run starts from its end: the arm's and the hand's joints,
the diagram's continuous state (σ) and the held torque (``Snapshot``).  The wait is cached per
start posture, controller and hand (one per process: ~1 s).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ptint_drake.controllers.hold import HOLD_NAME
from ptint_drake.worlds.base import new_simulator

SETTLE_TF = 1.0  # s
SETTLE_STARTS = (0.0, 2.0)  # s
SETTLE_HOLD = 0.5  # s


@dataclass(frozen=True)
class Snapshot:
    """The settled arm (module docstring): the arm's and the hand's [q; v], the diagram's
    continuous state and the control hold's torque (None without one)."""

    arm: np.ndarray
    hand: np.ndarray
    continuous: np.ndarray
    held: object


def _hold(diagram):
    return diagram.GetSubsystemByName(HOLD_NAME) if diagram.HasSubsystemNamed(HOLD_NAME) else None


def snapshot(run) -> Snapshot:
    """Simulate ``run`` (a catch run built to settle: its schedule one segment of ``SETTLE_TF``
    at the start pose) for ``SETTLE_TF + SETTLE_HOLD`` s; its end state."""
    simulator = new_simulator(run.diagram, config=run.simulator_config)
    context = simulator.get_mutable_context()
    st = run.station
    pc = st.plant.GetMyMutableContextFromRoot(context)
    st.plant.SetFreeBodyPose(pc, st.ball, run.parked)
    simulator.AdvanceTo(SETTLE_STARTS[-1] + SETTLE_TF + SETTLE_HOLD)
    hold = _hold(run.diagram)
    held = None if hold is None else hold.GetMyContextFromRoot(context).get_discrete_state(0).value().copy()
    return Snapshot(st.plant.GetPositionsAndVelocities(pc, st.arm).copy(),
                    st.plant.GetPositionsAndVelocities(pc, st.hand).copy(),
                    context.get_continuous_state_vector().CopyToVector(), held)


def start_from(snap: Snapshot, run, context) -> None:
    """Set ``run``'s root ``context`` (time 0) to the settled state ``snap``."""
    st = run.station
    pc = st.plant.GetMyMutableContextFromRoot(context)
    st.plant.SetPositionsAndVelocities(pc, st.arm, snap.arm)
    st.plant.SetPositionsAndVelocities(pc, st.hand, snap.hand)
    context.SetContinuousState(snap.continuous)
    hold = _hold(run.diagram)
    if hold is not None and snap.held is not None:
        hold.GetMyMutableContextFromRoot(context).SetDiscreteState(0, snap.held)
