"""The pick world's controller side alone, for a controller process that gets the world's state
in messages (``ptint drive``, ``hardware.drive``): what the controller aims at, the gripper's
commands and the grasp state, with no plant.

``AddPickControllerSide`` adds to a builder: ``PickTargets`` (what each segment aims at) fed from
the part tracker's reports or the camera's frames as received, ``GripperSequence`` (the plan's
gripper commands) and ``GraspObserver`` (``systems.hand.gripper``: the grasp state) fed from an input
of the gripper's reported fingers and drive forces.  The slots' places come from the scenario's
tray as declared (``scene.slot_pose``): no station is built.

=================  ==========  =============================================================
port (export)      size        meaning
=================  ==========  =============================================================
``tracked_poses``  18 a part   input (without an rgbd camera): the part tracker's report, per
                               part (scenario order) [p, v, R, ω] (``tracker``), read by
                               ``TrackedParts`` as ``ptint run`` reads the station's port
``depth_image``    image       input (an rgbd camera): the station's depth frame; the
                               estimators and ``EstimatedParts`` run here, the perception's
                               fits in a process of their own (``side.frames``: ``FrameProcess``)
``gripper``        6           input: [q_left, q_right, v_left, v_right] (m, m/s) and each
                               finger drive's force (N, − squeezes): ``GraspObserver``'s inputs
``grasp_state``    1           output: the observer's state (``systems.hand.gripper.GRASP_STATES``)
=================  ==========  =============================================================

``grasp_reads`` gives when ``world.PickRun`` reads that state (its grasp checks and the reads
every ``world.SENSE_PERIOD`` from a close command), on the control period's grid.
"""

from __future__ import annotations

from dataclasses import dataclass

from pydrake.common.value import AbstractValue
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.sensors import ImageDepth32F
from pydrake.systems.primitives import Demultiplexer, PassThrough

from ptint_drake.config.schema import Scenario
from ptint_drake.systems.hand.gripper import EMPTY, HOLDING, LOST, GraspObserver
from ptint_drake.worlds.base import LinkPorts
from ptint_drake.systems.perception.frame_process import FrameProcess
from ptint_drake.worlds.pick.camera import AddPartEstimates
from ptint_drake.worlds.pick.route import routed_plan
from ptint_drake.worlds.pick.cell import PROBE_PERIOD, REPLAY_PERIOD, place_positions, world_config
from ptint_drake.worlds.pick.targets import GripperSequence, PickTargets, PortTargets
from ptint_drake.worlds.pick.tracker import TRACKER_PORT, TrackedParts

CAMERA_NAME = "camera"  # the station's rgbd camera over LCM: DRAKE_RGBD_CAMERA_IMAGES_camera


def pick_link_ports(scenario: Scenario) -> LinkPorts:
    """What crosses ``ptint hardware``'s link beside the arm (``World.link_ports``): the gripper
    (its force limit) and the part tracker's reports of every part, or with an rgbd camera its
    depth frames instead (the drive runs the perception).  No truth port crosses it."""
    force, m = scenario.pick.gripper.max_force, scenario.measurement
    if m is not None and m.sensor == "rgbd":
        return LinkPorts(gripper_max_force=force, objects=0, camera=CAMERA_NAME,
                         camera_rate_hz=float(m.rate_hz))
    return LinkPorts(gripper_max_force=force, objects=len(scenario.pick.parts))


def plan_stands(state: int, read: str) -> bool:
    """The pick's grasp rule, the one ``ptint run`` (``world.PickRun``) and ``ptint drive``
    apply: at a grasp check (``read`` = "check") the plan stands when the gripper is ``holding``;
    at a read between the close command and the check ("sense") unless the fingers closed on
    nothing (``empty``) or lost the part (``lost``).  Otherwise the world plans anew (a retry, an
    abort, or at a check still ``closing``, a longer wait)."""
    return state == HOLDING if read == "check" else state not in (EMPTY, LOST)


class RunSampleTimes(LeafSystem):
    """No output, no state: publish events (that do nothing) every one of ``periods`` s from 0 —
    the sample times of ``ptint run``'s loggers (``run.PROBE_PERIOD``, ``run.REPLAY_PERIOD``), at
    which its simulator ends a step.  In the drive's diagram they end its steps at the same
    times, so that the controller's own state (σ, one explicit Euler step per interval) is
    integrated over the same sub-steps as in the one-process run, to the last bit (without them,
    the steps split at 1/30 s differ by round-off, which the contacts amplify: 2.2 µm at
    assembly_pick_place's last place)."""

    def __init__(self, periods: tuple):
        super().__init__()
        for period in periods:
            self.DeclarePeriodicPublishEvent(period, 0.0, lambda context: None)


@dataclass
class PickControllerSide:
    """What ``AddPickControllerSide`` added: the plan, the gripper sequence and observer, the parts'
    count, the gripper's force limit (N), the grasp reads (``grasp_reads``) and the target view."""

    plan: object
    sequence: GripperSequence
    observer: GraspObserver
    parts: int
    max_force: float
    reads: dict
    target: PortTargets
    # with an rgbd camera: the perception's fits in a process of their own (``FrameProcess``)
    frames: object = None

    def stands(self, utime: int, state: int) -> bool:
        """Whether the plan stands at the status of ``utime`` with the observer's ``state``
        (``plan_stands``; a time that is no grasp read: it stands)."""
        read = self.reads.get(utime)
        return read is None or plan_stands(state, read)


def grasp_reads(plan, period: float, sense: float) -> dict:
    """µs → "check" or "sense": the plan's grasp checks (not ``holding`` there: a new plan) and the
    reads every ``sense`` s (``world.SENSE_PERIOD``) between each close command and its check
    (``empty`` or ``lost`` there: a new plan), as ``world.PickRun`` stops for them."""
    out = {}
    for attempts in plan.attempts:
        for a in attempts:
            for j in range(1, int((a.check - a.close) / sense) + 1):
                out[int(round(round((a.close + j * sense) / period) * period * 1e6))] = "sense"
            out[int(round(a.check * 1e6))] = "check"
    return out


def AddPickControllerSide(builder: DiagramBuilder, scenario: Scenario, period: float,
                          sense: float) -> PickControllerSide:
    """The pick world's controller side in ``builder`` (module docstring), its ports exported;
    ``period``: the control period, ``sense``: ``grasp_reads``'s."""
    pick = scenario.pick
    frames = None
    plan = routed_plan(scenario)
    places = place_positions(world_config(scenario), plan)
    count = len(pick.parts)
    targets = builder.AddNamedSystem("pick_targets", PickTargets(plan, count, places))
    m = scenario.measurement
    if m is not None and m.sensor == "rgbd":  # the camera's frames in, the perception here
        depth = builder.AddNamedSystem("status_depth_image",
                                       PassThrough(AbstractValue.Make(ImageDepth32F())))
        estimates = AddPartEstimates(builder, depth.get_output_port(), scenario, fits_elsewhere=True)
        frames = FrameProcess(estimates.estimator, estimates.config, period)
        seen = estimates.parts
        for k in range(count):
            for what in (f"part_{k}_pose", f"part_{k}_rotation"):
                builder.Connect(seen.GetOutputPort(what), targets.GetInputPort(what))
        builder.ExportInput(depth.get_input_port(), "depth_image")
    else:  # the part tracker's reports in, read as ``ptint run`` reads them (``tracker``)
        tracked = builder.AddNamedSystem("tracked_parts", TrackedParts(count))
        for k in range(count):
            for what in (f"part_{k}_pose", f"part_{k}_rotation"):
                builder.Connect(tracked.GetOutputPort(what), targets.GetInputPort(what))
        builder.ExportInput(tracked.get_input_port(), TRACKER_PORT)
    builder.AddNamedSystem("run_sample_times", RunSampleTimes((PROBE_PERIOD, REPLAY_PERIOD)))
    sequence = builder.AddNamedSystem("gripper_sequence", GripperSequence(plan.commands, plan.widths))
    gripper = builder.AddNamedSystem("status_gripper", PassThrough(6))
    fingers = builder.AddNamedSystem("gripper_split", Demultiplexer([4, 2]))
    builder.Connect(gripper.get_output_port(), fingers.get_input_port(0))
    observer = builder.AddNamedSystem("grasp_observer", GraspObserver(
        pick.gripper.max_force, pick.gripper.speed, pick.width_tolerance, period=period))
    builder.Connect(fingers.get_output_port(0), observer.GetInputPort("finger_state"))
    builder.Connect(fingers.get_output_port(1), observer.GetInputPort("drive_force"))
    builder.Connect(sequence.GetOutputPort("command"), observer.GetInputPort("command"))
    builder.Connect(sequence.GetOutputPort("part_width"), observer.GetInputPort("part_width"))
    builder.ExportInput(gripper.get_input_port(), "gripper")
    builder.ExportOutput(observer.GetOutputPort("grasp_state"), "grasp_state")
    target = PortTargets(targets.GetOutputPort("target"), targets.GetOutputPort("target_rotation"))
    return PickControllerSide(plan, sequence, observer, count, pick.gripper.max_force,
                              grasp_reads(plan, period, sense), target, frames)
