"""The hardware side's controller slot: the arm's status out, torque commands in, over LCM, and
a safe stop on every fault.

``CommandLink`` is a discrete Drake system at the control period T, placed in the world's
controller slot in place of the controller and its zero-order hold (``ptint hardware`` puts it
there through the plugin path, ``controllers.plugin``).  At each tick t_k it reads the plant's
[q; v], publishes them as an ``lcmt_iiwa_status`` stamped t_k, takes the ``lcmt_iiwa_command``
answering that status (``HardwareSession.exchange``) and holds its torque until the next tick.
The plant is discrete with step T, and Drake's discrete ``MultibodyPlant`` takes its step before
the other discrete updates of the same time (measured on Drake 1.51.1 and 1.58: a zero-order hold
at t_k samples the arm after the plant's step at t_k), so the status of t_k is the arm after that
step and its command acts over the next one — the same timing as ``ptint run`` with
``controller.control_period`` = T on a discrete plant (``controllers.hold``).

The exchange itself — lockstep or real time, the checks on every command and the hold after a
fault — is ``session.HardwareSession``'s (its module docstring).

=============  ======  ================================================
port           size    meaning
=============  ======  ================================================
``state``      nq+nv   input: the plant's [q; v]
``target``     9       input: unused (the controller slot's protocol)
``actuation``  nu      output: the torque taken at the last tick (or the hold's)
=============  ======  ================================================
"""
from __future__ import annotations

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import LeafSystem
from pydrake.systems.sensors import ImageDepth32F

from ptint_drake.hardware.camera_link import frame_due
from ptint_drake.hardware.link import utime_of
from ptint_drake.worlds.base import TRACKED_SIZE, TRACKER_PORT
from ptint_drake.hardware.session import ACTIVE, LinkFault
from ptint_drake.robot.plant import actuator_effort_limits

HOLD_OMEGA = 40.0  # rad/s: the hold's natural frequency (critically damped); settles in ~0.15 s


class CommandLink(LeafSystem):
    """The hardware side's controller slot (module docstring), constructed by the plugin path
    inside ``ptint hardware`` (the active ``HardwareSession``, ``ACTIVE``).  ``plant``: the arm's
    model, for the hold's gravity compensation and its gains."""

    def __init__(self, plant, end_effector: str, params: dict):
        super().__init__()
        session = ACTIVE.get()
        if session is None:
            raise RuntimeError("CommandLink runs inside `ptint hardware` only (no LCM session)")
        self._session = session
        session.builds += 1
        self._replanned = session.builds > 1  # a world planned anew (a retry) and rebuilt the diagram
        self._plant = plant
        self._scratch = plant.CreateDefaultContext()  # a work area for the model's terms, no state
        nq, nv, nu = plant.num_positions(), plant.num_velocities(), plant.num_actuators()
        self._nq, self._nv, self._nu = nq, nv, nu
        self._B = plant.MakeActuationMatrix()
        self._limits = actuator_effort_limits(plant)
        self._state = self.DeclareVectorInputPort("state", nq + nv)
        self.DeclareVectorInputPort("target", 9)
        self._ports = session.ports
        # discrete state: [τ (nu), mode (0 commanded, 1 held), t_fault, q_hold (nq), (a gripper) its
        # opening command]
        self._xd = self.DeclareDiscreteState(nu + 2 + nq + (1 if self._ports else 0))
        if self._ports is not None:
            self._fingers = self.DeclareVectorInputPort("gripper_state", 4)
            self._drive = self.DeclareVectorInputPort("grip_force", 2)
            self._tracked = (self.DeclareVectorInputPort(TRACKER_PORT, TRACKED_SIZE * self._ports.objects)
                             if self._ports.objects else None)
            self._depth = (self.DeclareAbstractInputPort("depth_image", AbstractValue.Make(ImageDepth32F()))
                           if self._ports.camera else None)
            self.DeclareVectorOutputPort(
                "gripper_command",
                1,
                self._calc_gripper,
                prerequisites_of_calc={self.discrete_state_ticket(self._xd)},
            )
        self.DeclareInitializationDiscreteUpdateEvent(self._initialize)
        self.DeclarePeriodicDiscreteUpdateEvent(session.s.period, 0.0, self._update)
        self.DeclareVectorOutputPort(
            "actuation",
            nu,
            self._calc_actuation,
            prerequisites_of_calc={self.discrete_state_ticket(self._xd)},
        )

    def wire_station(self, builder, station, sequence):
        """In a world's diagram with a gripper (``World.link_ports``): the station's gripper, its
        pose tracker (``tracked_poses``: a sensor's reports, never a truth port) or its camera
        (``depth_image``) into the link, and the gripper command the link took (in place of the
        world's ``sequence``: the drive side runs it) out; returns that output port."""
        builder.Connect(station.GetOutputPort("gripper_state"), self._fingers)
        builder.Connect(station.GetOutputPort("grip_force"), self._drive)
        if self._tracked is not None:
            builder.Connect(station.GetOutputPort(TRACKER_PORT), self._tracked)
        if self._depth is not None:
            builder.Connect(station.GetOutputPort("depth_image"), self._depth)
        return self.GetOutputPort("gripper_command")

    def _calc_gripper(self, context, output) -> None:
        output.SetAtIndex(0, context.get_discrete_state(self._xd).value()[-1])

    def _extras(self, context, handshake: bool = False):
        """The station's companions of a status: fingers, drive forces, the tracker's report (or
        None), the depth image when a camera frame falls in this tick's period (or None:
        ``camera_link.frame_due``)."""
        if self._ports is None:
            return None
        tracked = self._tracked.Eval(context) if self._tracked is not None else None
        image = None
        if self._depth is not None and frame_due(context.get_time(), self._session.s.period,
                                                 self._ports.camera_rate_hz, handshake):
            image = self._depth.Eval(context)
        return self._fingers.Eval(context), self._drive.Eval(context), tracked, image

    def _initialize(self, context, discrete_state) -> None:
        """The hand-shake (``HardwareSession.handshake``) with the arm's start, once per session;
        with a gripper the gripper command it brings is the driver's at t = 0."""
        xd = context.get_discrete_state(self._xd).value().copy()
        session = self._session
        if session.handshake_s is None:
            x = self._state.Eval(context)
            session.handshake(x[: self._nq], x[self._nq :], np.zeros(self._nu), self._extras(context, True))
            if self._ports is not None:
                xd[-1] = session.gripper_opening(0)
        discrete_state.get_mutable_vector(self._xd).SetFromVector(xd)

    def _calc_actuation(self, context, output) -> None:
        output.SetFromVector(context.get_discrete_state(self._xd).value()[: self._nu])

    def hold_torque(self, q: np.ndarray, v: np.ndarray, q_hold: np.ndarray) -> np.ndarray:
        """Gravity compensation plus a critically damped position hold at ``q_hold`` (gains
        from the model's mass matrix diagonal, ``HOLD_OMEGA``), in actuator order, clipped."""
        plant, ctx = self._plant, self._scratch
        plant.SetPositions(ctx, q)
        plant.SetVelocities(ctx, np.zeros(self._nv))
        m = np.diag(plant.CalcMassMatrix(ctx))
        tau = -plant.CalcGravityGeneralizedForces(ctx) + m * (
            HOLD_OMEGA**2 * (q_hold - q) - 2.0 * HOLD_OMEGA * v
        )
        return np.clip(self._B.T @ tau, -self._limits, self._limits)

    def _update(self, context, discrete_state) -> None:
        session, nu, nq = self._session, self._nu, self._nq
        t = context.get_time()
        x = self._state.Eval(context)
        q, v = x[:nq], x[nq:]
        xd = context.get_discrete_state(self._xd).value().copy()
        tau, mode = xd[:nu], xd[nu]
        if mode == 0.0 and self._replanned:
            session._fail(
                t,
                "replan unsupported",
                f"the world planned anew before t = {t:.3f} s (a retry, an abort or a longer wait for "
                f"the grasp): replanning is not supported across processes",
            )
        if mode == 0.0 and session.record.fault is None and t < session.s.duration - 0.5 * session.s.period:
            command = session.exchange(t, q, v, tau.copy(), self._extras(context))
            if session.record.fault is None and command is not None:
                xd[:nu] = command
            if session.record.fault is None and self._ports is not None:
                opening = session.gripper_opening(utime_of(t) + utime_of(session.s.period))
                if opening is not None:
                    xd[-1] = opening
                    session.record.gripper_commands += 1
        if mode == 0.0 and session.record.fault is not None:
            mode, xd[nu + 1], xd[nu + 2 : nu + 2 + nq] = 1.0, t, q
        if mode == 1.0:
            xd[nu] = 1.0
            if t - xd[nu + 1] >= session.s.hold_time - 1e-9:
                raise LinkFault(session.record.fault)
            xd[:nu] = self.hold_torque(q, v, xd[nu + 2 : nu + 2 + nq])  # the gripper keeps its last command
        discrete_state.get_mutable_vector(self._xd).SetFromVector(xd)
