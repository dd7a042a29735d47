"""What the robot's driver adds to a command, and the command ``ptint drive`` sends for it
(``ptint drive --driver-mode``); the hardware side's refusal of a position command.

The scenario's controller computes the joint torque τ the arm must get.  A driver may add terms
of its own before the motors see it, so the drive takes them off (``DriverTerms.command``):

- ``torque``: a torque-only driver that adds nothing (``ptint hardware``): τ is sent.
- ``torque-gravity``: a torque-only driver that adds gravity compensation from its own model, as
  KUKA's FRI torque mode and Drake's ``SimIiwaDriver`` in ``kTorqueOnly`` do: τ − g(q) is sent
  (g from Drake's ``InverseDynamics`` in gravity-compensation mode on the arm's model, the term
  ``SimIiwaDriver`` adds).
- ``position-torque``: a position + torque driver, Drake's ``IiwaDriver`` default
  (``kPositionAndTorque``: an inverse-dynamics controller around the commanded positions plus the
  torque): the positions sent are the status's *measured* positions (the controller has no joint
  reference: it works in task space), so the driver's position error is zero when it applies the
  command; its inverse dynamics at zero acceleration, C(q, v)v − g(q), is taken off the torque.
  What stays is the driver's damping of the difference between its own velocity estimate (a
  finite difference of the commanded positions) and the arm's: measured on e(tf) in
  docs/hardware.md.

Every command carries ``num_joints`` = n and positions (the measured ones in the torque modes,
where a torque-only driver ignores them; Drake's ``IiwaCommandReceiver`` rejects 0 in any
position mode).  ``ptint hardware`` is a torque-only driver: it refuses a command whose positions
are not the status's measured ones (``position_refusal``) rather than ignore them.
"""

from __future__ import annotations

from typing import Optional

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.controllers import InverseDynamics

from ptint_drake.hardware.link import pack_command

DRIVER_MODES = ("torque", "torque-gravity", "position-torque")
POSITION_TOLERANCE = 1e-9  # rad: positions within this of the measured ones are an echo, not a command


class DriverTerms:
    """The command for a driver of ``mode`` (module docstring), with the arm's model ``plant``
    (continuous, finalized: what the driver's own model is assumed to be)."""

    def __init__(self, mode: str, plant: MultibodyPlant):
        if mode not in DRIVER_MODES:
            raise ValueError(f"--driver-mode: {mode!r} is not one of {', '.join(DRIVER_MODES)}")
        self.mode, self.n = mode, plant.num_velocities()
        self._plant = plant  # (pydrake's InverseDynamics keeps no reference to it)
        self._system = None
        if mode != "torque":
            kind = (InverseDynamics.InverseDynamicsMode.kGravityCompensation if mode == "torque-gravity"
                    else InverseDynamics.InverseDynamicsMode.kInverseDynamics)
            self._system = InverseDynamics(plant, kind)
            self._context = self._system.CreateDefaultContext()
            if mode == "position-torque":
                self._system.get_input_port_desired_acceleration().FixValue(self._context, np.zeros(self.n))

    def added(self, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The torque the driver adds at the state (q, v) (N·m; zero for ``torque``)."""
        if self._system is None:
            return np.zeros(self.n)
        self._system.get_input_port_estimated_state().FixValue(self._context, np.concatenate([q, v]))
        return np.array(self._system.get_output_port_generalized_force().Eval(self._context), dtype=float)

    def command(self, stamp: int, tau: np.ndarray, q: np.ndarray, v: np.ndarray) -> bytes:
        """The ``lcmt_iiwa_command`` stamped ``stamp`` that makes the arm get ``tau``: the torque
        less what the driver adds, and the measured positions ``q``."""
        return pack_command(stamp, tau - self.added(q, v), positions=q)


def position_refusal(positions: Optional[np.ndarray], measured: Optional[np.ndarray]) -> Optional[str]:
    """Why a torque-only driver refuses a command carrying ``positions`` for a status that
    measured ``measured``, or None (no positions, or the measured ones echoed)."""
    if positions is None or measured is None or len(positions) != len(measured):
        return None
    off = np.abs(positions - measured)
    if np.all(off <= POSITION_TOLERANCE):
        return None
    j = int(np.argmax(off))
    return (f"a position + torque command (joint {j} commanded {positions[j]:.6g} rad, measured "
            f"{measured[j]:.6g} rad): ptint hardware is a torque-only driver, it applies the torques "
            f"alone; send torque-only commands (num_joints 0, or the status's measured positions)")
