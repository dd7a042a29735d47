"""Wire the prescribed-time interceptor into an existing DiagramBuilder.

``AddPrescribedTimeInterceptor`` is to this package what
``AddMultibodyPlantSceneGraph`` is to Drake: give it a builder, a (finalized)
MultibodyPlant already added to that builder, the frame whose origin must
intercept, the schedule and one target per segment, and it adds

    TargetSource ─┐
    TimeBaseGenerator ─┼─> SlidingSurface ─> SlidingModeController ─> plant actuation
    plant state ─> TaskSpaceKinematics ─┘                ↑ J

returning the handles of every block so the caller can log, export or
re-wire their ports.  Every actuated joint of the plant is driven; the plant
must actuate each of its velocities (nv = nu).
"""

from dataclasses import dataclass
from typing import Optional, Sequence

from pydrake.systems.framework import InputPort, OutputPort
from pydrake.systems.primitives import Demultiplexer

from ptint_drake.controllers.ptsmc.gains import ControllerGains
from ptint_drake.controllers.ptsmc.interceptor import PrescribedTimeInterceptor
from ptint_drake.controllers.ptsmc.law import SlidingModeController, null_space_terms
from ptint_drake.controllers.ptsmc.sliding_surface import SlidingSurface
from ptint_drake.systems.task.error import TASK_DIM, TASK_MIN_JOINTS
from ptint_drake.systems.task.kinematics import TaskSpaceKinematics
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.systems.task.signals import TARGET_PORT_SIZE
from ptint_drake.systems.task.targets import TargetSource
from ptint_drake.systems.task.tbg import TimeBaseGenerator


@dataclass(frozen=True)
class InterceptorHandles:
    """The systems that ``AddPrescribedTimeInterceptor`` added: the five blocks, or
    (``fused=True``) the single ``PrescribedTimeInterceptor`` in ``fused``."""

    schedule: Schedule
    tbg: Optional[TimeBaseGenerator] = None
    targets: Optional[TargetSource] = None
    kinematics: Optional[TaskSpaceKinematics] = None
    surface: Optional[SlidingSurface] = None
    controller: Optional[SlidingModeController] = None
    fused: Optional[PrescribedTimeInterceptor] = None
    target_input: Optional[InputPort] = None  # with targets=None: where [x_r, ẋ_r, ẍ_r] goes in
    # with targets=None and an orientation task: where [R_r, ω_r, ω̇_r] goes in
    rotation_input: Optional[InputPort] = None


def AddPrescribedTimeInterceptor(builder, plant, frame, schedule: Schedule,
                                 targets: Optional[Sequence], gains: ControllerGains = ControllerGains(),
                                 connect_actuation: bool = True, name: str = "interceptor",
                                 fused: bool = False,
                                 state_port: Optional[OutputPort] = None,
                                 posture=None) -> InterceptorHandles:
    """Add the interceptor's blocks to ``builder`` and connect them to ``plant``.

    With ``connect_actuation=False`` the controller's ``u`` port is left for the
    caller (e.g. to add saturation or a disturbance before the plant).
    ``fused=True`` adds the same computation as one ``PrescribedTimeInterceptor``
    system (several times faster to simulate; fewer ports to inspect).
    ``targets=None`` builds it without any target object: the handles'
    ``target_input`` ([x_r, ẋ_r, ẍ_r] of the active segment, ``signals.TARGET_PORT``) is for
    the caller to connect, e.g. to a Kalman filter (and, with an orientation ``gains.task``,
    ``rotation_input``: [R_r, ω_r, ω̇_r], ``signals.TARGET_ROTATION``).
    ``state_port`` is where [q; v] comes from (default: the plant's state output; e.g. a station's
    exported ``state``).
    ``posture``: the joint positions the optional null-space term (``gains.null_space_damping``,
    redundant arms) pulls toward (default: the plant's default positions).
    """
    if not plant.is_finalized():
        raise ValueError("plant: must be finalized before adding the interceptor")
    nv = plant.num_velocities()
    if plant.num_actuated_dofs() != nv:
        raise ValueError(
            f"robot.model: the plant must actuate every velocity (nv = {nv}, "
            f"actuated = {plant.num_actuated_dofs()})")
    if nv < TASK_MIN_JOINTS[gains.task]:
        raise ValueError(f"controller.task: {gains.task!r} needs at least {TASK_MIN_JOINTS[gains.task]} "
                         f"joints, the arm has {nv}")

    state_port = state_port or plant.get_state_output_port()
    if fused:
        system = builder.AddNamedSystem(name, PrescribedTimeInterceptor(
            plant=plant, frame=frame, schedule=schedule, gains=gains, targets=targets, posture=posture))
        builder.Connect(state_port, system.GetInputPort("state"))
        if connect_actuation:
            builder.Connect(system.GetOutputPort("u"), plant.get_actuation_input_port())
        return InterceptorHandles(schedule, fused=system, target_input=(
            system.GetInputPort("target") if targets is None else None), rotation_input=(
            system.GetInputPort("target_rotation") if system.has_rotation_input else None))

    return _add_blocks(builder, plant, frame, schedule=schedule, targets=targets, gains=gains,
                       connect_actuation=connect_actuation, name=name, state_port=state_port,
                       posture=posture)


def _add_blocks(builder, plant, frame, *, schedule, targets, gains, connect_actuation, name, state_port,
                posture) -> InterceptorHandles:
    """The five wired blocks of paper Fig. 1 (see ``AddPrescribedTimeInterceptor``)."""
    nv, rotation = plant.num_velocities(), gains.task != "position"
    tbg = builder.AddNamedSystem(f"{name}_tbg", TimeBaseGenerator(
        schedule, gains.epsilon, gains.delta, gains.alpha_hold))
    rotation_input = None
    if targets is None:
        # x_r | ẋ_r | ẍ_r
        source = builder.AddNamedSystem(f"{name}_target", Demultiplexer(TARGET_PORT_SIZE, 3))
        x_r, xdot_r = source.get_output_port(0), source.get_output_port(1)
    else:
        source = builder.AddNamedSystem(f"{name}_target", TargetSource(schedule, targets))
        x_r, xdot_r = source.GetOutputPort("x_r"), source.GetOutputPort("xdot_r")
    kin = builder.AddNamedSystem(f"{name}_kinematics", TaskSpaceKinematics(
        plant, frame, gains.task, gains.rot_scale))
    surface = builder.AddNamedSystem(f"{name}_surface", SlidingSurface(
        schedule, gains.Lambda, gains.k, gains.switching, gains.phi, gains.sigma_policy, gains.k_hold,
        gains.task, gains.rot_scale))
    null_space = null_space_terms(gains, plant, posture)
    ctrl = builder.AddNamedSystem(f"{name}_controller", SlidingModeController(
        nv, gains.K, plant.MakeActuationMatrix(), gains.pinv_damping, null_space, TASK_DIM[gains.task]))
    if null_space is not None:
        builder.Connect(state_port, ctrl.GetInputPort("state"))

    builder.Connect(state_port, kin.get_state_input_port())
    for port in ("x", "xdot") + (("R", "omega") if rotation else ()):
        builder.Connect(kin.GetOutputPort(port), surface.GetInputPort(port))
    if rotation and targets is not None:
        builder.Connect(source.GetOutputPort("target_rotation"), surface.GetInputPort("target_rotation"))
    elif rotation:
        rotation_input = surface.GetInputPort("target_rotation")
    builder.Connect(x_r, surface.GetInputPort("x_r"))
    builder.Connect(xdot_r, surface.GetInputPort("xdot_r"))
    builder.Connect(tbg.GetOutputPort("alpha"), surface.GetInputPort("alpha"))
    builder.Connect(tbg.GetOutputPort("segment"), surface.GetInputPort("segment"))
    builder.Connect(surface.GetOutputPort("s_x"), ctrl.GetInputPort("s_x"))
    builder.Connect(kin.GetOutputPort("J"), ctrl.GetInputPort("J"))
    if connect_actuation:
        builder.Connect(ctrl.GetOutputPort("u"), plant.get_actuation_input_port())
    return InterceptorHandles(schedule, tbg, source, kin, surface, ctrl,
                              target_input=source.get_input_port() if targets is None else None,
                              rotation_input=rotation_input)
