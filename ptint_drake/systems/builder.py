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

from ptint_drake.systems.controller import SlidingModeController
from ptint_drake.systems.interceptor import PrescribedTimeInterceptor
from ptint_drake.systems.kinematics import TaskSpaceKinematics
from ptint_drake.systems.schedule import Schedule
from ptint_drake.systems.sliding_surface import SlidingSurface
from ptint_drake.systems.targets import TargetSource
from ptint_drake.systems.tbg import TimeBaseGenerator


@dataclass
class ControllerGains:
    """The paper's gains (section 3.1) as defaults, and the choices it leaves open.

    K (N·m·s/rad) and Lambda may also be given as diagonals (sequences) from Python;
    the scenario schema (``scenario.ControllerConfig``, which extends this class)
    takes scalars.  Annotations are real types (no postponed evaluation in this
    module) because Drake's ``yaml_load_typed`` reads them.
    """

    K: float = 50.0
    Lambda: float = 5.0
    k: float = 3.0  # 1/s, decay of s_d
    epsilon: float = 1.0e-6
    delta: float = 1.0e-6
    alpha_hold: float = 0.0  # 1/s, α after tf
    switching: str = "tanh"  # sign | tanh | sat
    phi: float = 0.01  # m/s, boundary-layer width
    sigma_policy: str = "keep"  # keep | reset σ at a new segment
    k_hold: float = 50.0  # 1/s, decay of s_d after tf
    pinv_damping: float = 0.0  # m/rad: λ of the damped pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹; 0 = exact


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


def AddPrescribedTimeInterceptor(builder, plant, frame, schedule: Schedule,
                                 targets: Sequence, gains: ControllerGains = ControllerGains(),
                                 connect_actuation: bool = True,
                                 name: str = "interceptor", fused: bool = False) -> InterceptorHandles:
    """Add the interceptor's blocks to ``builder`` and connect them to ``plant``.

    With ``connect_actuation=False`` the controller's ``u`` port is left for the
    caller (e.g. to add saturation or a disturbance before the plant).
    ``fused=True`` adds the same computation as one ``PrescribedTimeInterceptor``
    system (several times faster to simulate; fewer ports to inspect).
    """
    if not plant.is_finalized():
        raise ValueError("plant: must be finalized before adding the interceptor")
    nv = plant.num_velocities()
    if plant.num_actuated_dofs() != nv:
        raise ValueError(
            f"robot.model: the plant must actuate every velocity (nv = {nv}, "
            f"actuated = {plant.num_actuated_dofs()})")
    if nv < 3:
        raise ValueError(f"robot.model: at least 3 joints are needed for 3-D interception, got {nv}")

    if fused:
        system = builder.AddNamedSystem(name, PrescribedTimeInterceptor(
            plant, frame, schedule, targets, gains.K, gains.Lambda, gains.k, gains.epsilon,
            gains.delta, gains.alpha_hold, gains.switching, gains.phi, gains.sigma_policy,
            gains.k_hold, gains.pinv_damping))
        builder.Connect(plant.get_state_output_port(), system.GetInputPort("state"))
        if connect_actuation:
            builder.Connect(system.GetOutputPort("u"), plant.get_actuation_input_port())
        return InterceptorHandles(schedule, fused=system)

    tbg = builder.AddNamedSystem(f"{name}_tbg", TimeBaseGenerator(
        schedule, gains.epsilon, gains.delta, gains.alpha_hold))
    source = builder.AddNamedSystem(f"{name}_target", TargetSource(schedule, targets))
    kin = builder.AddNamedSystem(f"{name}_kinematics", TaskSpaceKinematics(plant, frame))
    surface = builder.AddNamedSystem(f"{name}_surface", SlidingSurface(
        schedule, gains.Lambda, gains.k, gains.switching, gains.phi, gains.sigma_policy, gains.k_hold))
    ctrl = builder.AddNamedSystem(f"{name}_controller", SlidingModeController(
        nv, gains.K, plant.MakeActuationMatrix(), gains.pinv_damping))

    builder.Connect(plant.get_state_output_port(), kin.get_state_input_port())
    builder.Connect(kin.GetOutputPort("x"), surface.GetInputPort("x"))
    builder.Connect(kin.GetOutputPort("xdot"), surface.GetInputPort("xdot"))
    builder.Connect(source.GetOutputPort("x_r"), surface.GetInputPort("x_r"))
    builder.Connect(source.GetOutputPort("xdot_r"), surface.GetInputPort("xdot_r"))
    builder.Connect(tbg.GetOutputPort("alpha"), surface.GetInputPort("alpha"))
    builder.Connect(tbg.GetOutputPort("segment"), surface.GetInputPort("segment"))
    builder.Connect(surface.GetOutputPort("s_x"), ctrl.GetInputPort("s_x"))
    builder.Connect(kin.GetOutputPort("J"), ctrl.GetInputPort("J"))
    if connect_actuation:
        builder.Connect(ctrl.GetOutputPort("u"), plant.get_actuation_input_port())
    return InterceptorHandles(schedule, tbg, source, kin, surface, ctrl)
