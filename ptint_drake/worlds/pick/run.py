"""Build a pick-and-place scenario's diagram: the pick station, the controller, the plan.

``build_pick`` wires ``station.MakePickStation`` (discrete plant with contact), the scenario's
controller in its slot (``controllers.AddControllerTo``: the arm's [q; v] in, its torques out
through the drive's zero-order hold and the effort limits; the arm's kinematics from a plant of
the arm's model file alone — the controller knows nothing of the gripper, the parts or the
payload), ``PickTargets`` (what each segment aims at, from the part tracker's reports,
``tracker``, or the camera's estimates),
``GripperSequence`` (open, close at the prescribed time, open), ``GraspObserver`` (the grasp
state from the fingers' width, speed and drive force: ``systems.hand.gripper``) and ``PickProbe``
(poses, contacts and pad forces, recorded every ``PROBE_PERIOD``).  ``world.PickWorld`` runs it
through the one runner
(``worlds.runner``), stopping at every segment's start and end; its metrics carry the segments and
``picks`` (``metrics``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput, Saturation

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.part_shape import part_height
from ptint_drake.config.schema import Scenario, default_simulator
from ptint_drake.controllers import AddControllerTo, ControllerHandles
from ptint_drake.robot.plant import actuator_effort_limits, nominal_plant
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.hand.gripper import GraspObserver
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.worlds.pick.camera import AddPartEstimates, PartEstimates
from ptint_drake.worlds.pick.cell import PROBE_PERIOD, REPLAY_PERIOD, place_positions, world_config
from ptint_drake.worlds.pick.line.plan import line_plan
from ptint_drake.worlds.pick.line.seen import AddLineCamera, LineCamera
from ptint_drake.worlds.pick.probe import PickProbe
from ptint_drake.worlds.pick.route import routed_plan
from ptint_drake.worlds.pick.station import MakePickStation, PickStation
from ptint_drake.worlds.pick.targets import GripperSequence, PickTargets, PortTargets
from ptint_drake.worlds.pick.tracker import TRACKER_PORT, TrackedParts
from ptint_drake.worlds.pick.tasks import PickPlan, Replan
from ptint_drake.worlds.stateless_derivatives import install_stateless_derivatives

@dataclass
class PickBuilt:
    """A built pick diagram and its handles."""

    diagram: object
    station: PickStation
    controller: ControllerHandles
    plan: PickPlan
    targets: PickTargets
    loggers: dict
    arm: object  # the arm's model alone (continuous, nominal): the controller's kinematics
    limits: np.ndarray  # the arm's effort limits (N·m)
    observer: GraspObserver = None  # the grasp state (systems.hand.gripper)
    estimates: PartEstimates = None  # with an rgbd camera: what the pick aims at (pick.camera)
    # with an rgbd camera: the same plan's targets read off the simulated parts (the metrics' truth)
    true_targets: PickTargets = None
    line_camera: LineCamera = None  # a line seen by an rgbd camera: its tracks (line.seen)

    def part_system(self):
        """The system whose ``part_k_pose`` / ``part_k_rotation`` the targets read: the camera's
        estimates (a line's: its tracks, ``line.seen.LineSeenParts``), or the part tracker's
        reports (``tracker.TrackedParts``)."""
        if self.line_camera is not None:
            return self.line_camera.parts
        if self.estimates is not None:
            return self.estimates.parts
        return self.diagram.GetSubsystemByName("tracked_parts")


def build_pick(scenario: Scenario, replans: tuple[Replan, ...] = (), planning=None) -> PickBuilt:
    """The pick scenario's diagram (module docstring), its plan with the ``replans`` a run decided;
    ``planning``: a line's plan is made from it, the scenario as the controller side believes it
    (``line.driver.LineDriver.planning``: the tracked parts where they are seen)."""
    builder = DiagramBuilder()
    station = MakePickStation(world_config(scenario), scenario.measurement)
    st = builder.AddNamedSystem("pick_station", station.diagram)
    arm = nominal_plant(scenario)
    # the way around the base where one is needed (route); a line's begins with its idle segment
    plan = (line_plan if scenario.pick.line is not None else routed_plan)(planning or scenario, replans, arm)
    n = len(station.parts)
    places = place_positions(station.config, plan)
    targets = builder.AddNamedSystem("pick_targets", PickTargets(plan, n, places))
    parts, estimates, true_targets, line_camera = _part_source(builder, st, scenario, plan, places)
    _connect_parts(builder, parts, targets, n)
    limits = actuator_effort_limits(arm)
    saturation = builder.AddNamedSystem("saturation", Saturation(-limits, limits))
    builder.Connect(saturation.get_output_port(), st.GetInputPort("actuation"))
    view = PortTargets(targets.GetOutputPort("target"), targets.GetOutputPort("target_rotation"))
    handles = AddControllerTo(builder, plant=arm, frame=arm.GetFrameByName(scenario.robot.end_effector),
                              schedule=plan.schedule, state=st.GetOutputPort("state"),
                              actuation=saturation.get_input_port(), scenario=scenario, target=view)
    sequence = builder.AddNamedSystem("gripper_sequence", GripperSequence(plan.commands, plan.widths))
    gripper = sequence.GetOutputPort("command")
    wire = getattr(handles.system, "wire_station", None)  # a slot system that commands the gripper itself
    if wire is not None:  # (``ptint hardware``'s link: the commands come from the drive process)
        gripper = wire(builder, st, sequence)
    builder.Connect(gripper, st.GetInputPort("gripper_command"))
    observer = builder.AddNamedSystem("grasp_observer", GraspObserver(
        scenario.pick.gripper.max_force, scenario.pick.gripper.speed, scenario.pick.width_tolerance,
        period=station.config.time_step))
    builder.Connect(st.GetOutputPort("gripper_state"), observer.GetInputPort("finger_state"))
    builder.Connect(st.GetOutputPort("grip_force"), observer.GetInputPort("drive_force"))
    builder.Connect(gripper, observer.GetInputPort("command"))
    builder.Connect(sequence.GetOutputPort("part_width"), observer.GetInputPort("part_width"))
    AddPickProbe(builder, st, station)
    loggers = {"grasp_state": LogVectorOutput(observer.GetOutputPort("grasp_state"), builder, PROBE_PERIOD),
               "grip_force": LogVectorOutput(st.GetOutputPort("grip_force"), builder, PROBE_PERIOD),
               "gripper_state": LogVectorOutput(st.GetOutputPort("gripper_state"), builder, PROBE_PERIOD),
               "state": LogVectorOutput(st.GetOutputPort("state"), builder, PROBE_PERIOD),
               "target": LogVectorOutput(targets.GetOutputPort("target"), builder, PROBE_PERIOD),
               "plant_state": LogVectorOutput(st.GetOutputPort("plant_state"), builder, REPLAY_PERIOD)}
    loggers |= {f"controller/{name}": LogVectorOutput(port, builder, PROBE_PERIOD)
                for name, port in handles.log_ports.items()}
    if estimates is not None:
        loggers |= _camera_loggers(builder, st, estimates, true_targets, n)
    if line_camera is not None:  # every frame's tracks (line.metrics: the IDSW, when each part was seen)
        loggers["tracks"] = LogVectorOutput(line_camera.perception.GetOutputPort("tracks"), builder,
                                            1.0 / scenario.measurement.rate_hz)
    diagram = builder.Build()
    diagram.set_name(scenario.name or "pick")
    install_stateless_derivatives(diagram)  # as simulation.build: Drake's nanobind bindings
    return PickBuilt(diagram, station, handles, plan, targets, loggers, arm, limits, observer, estimates,
                     true_targets, line_camera)


def _part_source(builder: DiagramBuilder, st, scenario: Scenario, plan: PickPlan, places: list) -> tuple:
    """(what the targets read, the camera's estimates, the targets read off the simulated parts, a
    line's camera): the part tracker's reports (a sensor: the station's truth ports are the
    metrics'), the camera's estimates of the declared parts, or a line's tracks (``line.seen``)."""
    n = len(scenario.pick.parts)
    if scenario.measurement is None or scenario.measurement.sensor != "rgbd":
        parts = builder.AddNamedSystem("tracked_parts", TrackedParts(n))
        builder.Connect(st.GetOutputPort(TRACKER_PORT), parts.get_input_port())
        return parts, None, None, None
    if scenario.pick.line is not None:  # a line's tracks of undeclared parts
        line_camera = AddLineCamera(builder, st.GetOutputPort("depth_image"), scenario)
        return line_camera.parts, None, None, line_camera
    estimates = AddPartEstimates(builder, st.GetOutputPort("depth_image"), scenario)
    true_targets = builder.AddNamedSystem("pick_targets_true", PickTargets(plan, n, places))
    _connect_parts(builder, st, true_targets, n)
    return estimates.parts, estimates, true_targets, None


def _connect_parts(builder: DiagramBuilder, parts, targets: PickTargets, n: int) -> None:
    """``parts``' ``part_k_pose`` / ``part_k_rotation`` into ``targets``' inputs."""
    for k in range(n):
        builder.Connect(parts.GetOutputPort(f"part_{k}_pose"), targets.GetInputPort(f"part_{k}_pose"))
        builder.Connect(parts.GetOutputPort(f"part_{k}_rotation"), targets.GetInputPort(f"part_{k}_rotation"))


def _camera_loggers(builder: DiagramBuilder, st, estimates: PartEstimates, true_targets: PickTargets,
                    n: int) -> dict:
    """With a camera, every ``PROBE_PERIOD``: the targets read off the simulated parts, and per part
    the simulated and the estimated pose and rotation and the fit the estimators were last given
    (``measurement_k``: [stamp, x, y, z, valid]; ``measured_rotation_k``: [stamp, R, valid])."""
    out = {"target_true": LogVectorOutput(true_targets.GetOutputPort("target"), builder, PROBE_PERIOD)}
    seen, fits = estimates.parts, estimates.perception
    for k in range(n):
        for name, port in ((f"part_true_{k}", st.GetOutputPort(f"part_{k}_pose")),
                           (f"part_true_rotation_{k}", st.GetOutputPort(f"part_{k}_rotation")),
                           (f"part_estimate_{k}", seen.GetOutputPort(f"part_{k}_pose")),
                           (f"part_estimate_rotation_{k}", seen.GetOutputPort(f"part_{k}_rotation")),
                           (f"fit_{k}", fits.GetOutputPort(f"measurement_{k}")),
                           (f"fit_rotation_{k}", fits.GetOutputPort(f"measured_rotation_{k}"))):
            out[name] = LogVectorOutput(port, builder, PROBE_PERIOD)
    if fits.HasOutputPort("tracks"):  # every frame's tracks (part_tracks.track_metrics: the IDSW)
        out["tracks"] = LogVectorOutput(fits.GetOutputPort("tracks"), builder, PROBE_PERIOD)
    return out


def AddPickProbe(builder: DiagramBuilder, st, station: PickStation) -> PickProbe:
    """Add ``PickProbe`` as ``pick_probe``, fed by the station system ``st`` (``station``'s
    diagram in ``builder``): its contact results and the plant's [q; v], recorded every
    ``PROBE_PERIOD``.  Returns the probe (``probe.log(context)`` after the run)."""
    probe = builder.AddNamedSystem("pick_probe", _probe(station))
    builder.Connect(st.GetOutputPort("contact_results"), probe.GetInputPort("contact_results"))
    builder.Connect(st.GetOutputPort("plant_state"), probe.GetInputPort("plant_state"))
    return probe


def _probe(station: PickStation) -> PickProbe:
    plant = station.plant
    robot = [b for m in (station.arm, station.gripper) for b in plant.GetBodyIndices(m)]
    tool = plant.GetFrameByName("fingertip_center", station.gripper)
    return PickProbe(plant, [b.index() for b in station.parts],
                     [j.child_body().index() for j in station.belts],
                     plant.GetBodyByName("left_finger", station.gripper).index(),
                     plant.GetBodyByName("right_finger", station.gripper).index(), robot,
                     (tool.body().index(), tool.GetFixedPoseInBodyFrame()), station.collision_probe,
                     station.body_of_geometry, PROBE_PERIOD)


def pick_logs(built: PickBuilt, context) -> dict:
    """{name: (times, rows)} of a pick run's loggers in ``context`` (the diagram's root context),
    with the probe's samples (``PickProbe.log``) split into ``probe``, ``grip_forces`` and
    ``collisions`` (``PickProbe.blocks``)."""
    logs = {name: (logger.FindLog(context).sample_times().copy(), logger.FindLog(context).data().T.copy())
            for name, logger in built.loggers.items()}
    probe = built.diagram.GetSubsystemByName("pick_probe")
    t, values = probe.log(probe.GetMyContextFromRoot(context))
    logs |= {name: (t, np.ascontiguousarray(values[:, block])) for name, block in probe.blocks.items()}
    return logs


def pick_simulator(scenario: Scenario) -> SimulatorConfig:
    """The scenario's ``simulator``, except that the default (error-controlled RK3) becomes one
    explicit Euler step per control period: on the discrete plant, between two samples, the plant's
    state and the held torque are constant, so the controller's own state (σ) sees constant inputs
    and one step per sample integrates it as a digital drive would.  Measured on
    conveyor_pick_place: the same picks (place error 0.156 mm both) at 2.2× less CPU time."""
    if repr(scenario.simulator) != repr(default_simulator()):  # (config structs have no ==)
        return scenario.simulator
    period = scenario.controller.control_period
    return SimulatorConfig(integration_scheme="explicit_euler", use_error_control=False, max_step_size=period,
                           accuracy=scenario.simulator.accuracy)


def check_pick_plant(scenario: Scenario) -> None:
    """ScenarioError for plant deviations a pick scenario does not take."""
    p = scenario.plant
    if p.payload_kg != 0.0:
        raise ScenarioError("plant.payload_kg: not used in a pick scenario (the part is the payload)")
    if p.damping_scale != 1.0 or p.coulomb or p.disturbance.amplitude or p.disturbance.step:
        raise ScenarioError("plant: a pick scenario takes mass_scale only")


def check_pick_reachable(scenario: Scenario, built: PickBuilt) -> None:
    """Before a run: every task's grasp (the part's nominal place on its belt at the prescribed grasp
    time), its lift point and its slot (and the carry above it), solved from one to the next, then
    every slot no task uses (``_check_slots``) must be reachable from above (Drake's
    InverseKinematics, the model's joint limits); a ScenarioError naming the field: a slot out of
    reach is ``pick.tray.slots[j]`` (the tray's centre and the slot's offset put it there), a bin's
    drop point out of reach ``pick.bins[j]``."""
    arm = built.arm
    frame = arm.GetFrameByName(scenario.robot.end_effector)
    plan, config = built.plan, built.station.config
    belts = {b.name: b for b in config.belts}
    guess = np.radians(scenario.robot.initial_q_deg)
    context = built.station.plant.CreateDefaultContext()
    guesses = [guess]
    for k, task in enumerate(scenario.pick.tasks):
        part_index = [p.name for p in config.parts].index(task.part)
        belt = belts[config.parts[part_index].belt]
        start = built.station.parts[part_index].EvalPoseInWorld(context).translation()
        grasp = start + belt.speed * plan.grasp_times[k] * np.asarray(belt.direction)
        i = plan.segment_index(k, "place")  # (an outgoing belt's place: where it is at the place time)
        place = built.targets.places[i] + np.asarray(plan.segments[i].ride) * plan.schedule.segments[i].end
        for where, x in ((f"pick.tasks[{k}].part", grasp), (f"pick.tasks[{k}].lift_height",
                                                           grasp + [0, 0, task.lift_height]),
                         (_place_field(scenario, task), place), (f"pick.tasks[{k}].lift_height",
                                                           place + [0, 0, task.lift_height])):
            solution = inverse_kinematics(arm, frame, np.asarray(x), guess, down=True)
            if solution is None:
                raise ScenarioError(f"{where}: {np.round(x, 3).tolist()} m is outside what the arm reaches "
                                    f"from above")
            guess = solution
        guesses.append(guess)
    _check_slots(scenario, built, frame, guesses, context)


def _place_field(scenario: Scenario, task) -> str:
    """The field that puts a task's place where it is: its slot's, or its bin's."""
    if task.bin:
        j = [b.name for b in scenario.pick.bins].index(task.bin)
        return f"pick.bins[{j}] (its center and depth)"
    if task.belt:
        return f"pick.tasks[{scenario.pick.tasks.index(task)}].belt_at"
    return _slot_field(task.slot)


def _slot_field(j: int) -> str:
    return f"pick.tray.slots[{j}] (pick.tray.center and the slot's offset)"


def _check_slots(scenario: Scenario, built: PickBuilt, frame, guesses: list, context) -> None:
    """ScenarioError naming ``pick.tray.slots[j]`` when slot j, one no task uses, is outside what
    the arm reaches from above (solved from each of ``guesses``: the start posture and the tasks'
    carries): at half the lowest part's height above the tray and ``lift_height`` above that."""
    tasks, used = scenario.pick.tasks, {t.slot for t in scenario.pick.tasks}
    height = min(part_height(p.shape, p.size) for p in built.station.config.parts)
    lift = max(t.lift_height for t in tasks)
    for j, slot in enumerate(built.station.slots):
        if j in used:
            continue
        x = slot.CalcPoseInWorld(context).translation() + [0.0, 0.0, height / 2]
        for where in (x, x + [0.0, 0.0, lift]):
            if all(inverse_kinematics(built.arm, frame, where, q, down=True) is None for q in guesses):
                raise ScenarioError(f"{_slot_field(j)}: {np.round(where, 3).tolist()} m is outside what "
                                    f"the arm reaches from above")


def pick_series(built: PickBuilt, logs: dict) -> dict:
    """The run's time series (every ``PROBE_PERIOD``): the probe, the fingers, the arm's q, v, the
    tool point x, ẋ (forward kinematics of the logged arm state), the target the controller aimed
    at (``target``) and the error against the truth (``e_true``, ``edot_true``: against the same
    plan's target read off the simulated parts — without a camera that *is* ``target``), the
    controller's telemetry (``tau`` commanded, ``tau_applied`` after the effort limits), and the
    whole plant's state every ``REPLAY_PERIOD`` (``replay_t``, ``plant_state``) for the replay.
    With a camera also: ``target_true``, ``e_estimate`` / ``edot_estimate`` (against what the
    controller aimed at, the estimate) and per part k, on the same times, ``part_true_k`` /
    ``part_estimate_k`` ([x (3), R row-major (9)]) and ``fit_k`` ([stamp, x, y, z, valid, R (9)]:
    the last fit the estimators were given), and ``tracks_t`` / ``tracks``: the perception's tracks
    log (``track_system.TrackingPartPoseEstimator``'s ``tracks`` output, when it has one)."""
    t, state = logs["state"]
    nq = built.arm.num_positions()
    kinematics = FrameKinematics(built.arm, built.arm.GetFrameByName(built.station.config.end_effector))
    x, xdot = np.empty((len(t), 3)), np.empty((len(t), 3))
    for k in range(len(t)):
        x[k], xdot[k], _ = kinematics.compute(state[k, :nq], state[k, nq:])
    target = logs["target"][1]
    controller = {name.split("/", 1)[1]: data for name, (_, data) in logs.items()
                  if name.startswith("controller/")}
    series = dict(built.controller.telemetry(controller | {"t": t, "state": state}))
    truth = logs["target_true"][1] if "target_true" in logs else target
    series |= {"t": t, "q": state[:, :nq], "v": state[:, nq:], "x": x, "xdot": xdot, "target": target,
               "e_true": x - truth[:, 0:3], "edot_true": xdot - truth[:, 3:6],
               "tau_applied": np.clip(series["tau"], -built.limits, built.limits),
               "probe": logs["probe"][1], "grip_force": logs["grip_force"][1],
               "gripper_state": logs["gripper_state"][1], "state": state,
               "grip_forces": logs["grip_forces"][1], "grasp_state": logs["grasp_state"][1][:, 0],
               "replay_t": logs["plant_state"][0], "plant_state": logs["plant_state"][1]}
    if "target_true" in logs:
        series |= {"target_true": truth, "e_estimate": x - target[:, 0:3],
                   "edot_estimate": xdot - target[:, 3:6]}
        for k in range(len(built.station.parts)):
            series[f"part_true_{k}"] = np.hstack([logs[f"part_true_{k}"][1][:, 0:3],
                                                  logs[f"part_true_rotation_{k}"][1][:, 0:9]])
            series[f"part_estimate_{k}"] = np.hstack([logs[f"part_estimate_{k}"][1][:, 0:3],
                                                      logs[f"part_estimate_rotation_{k}"][1][:, 0:9]])
            series[f"fit_{k}"] = np.hstack([logs[f"fit_{k}"][1], logs[f"fit_rotation_{k}"][1][:, 1:10]])
    if "tracks" in logs:  # the perception's tracks (track_system: stamp, per slot id … class)
        series["tracks_t"], series["tracks"] = logs["tracks"]
    return series


def segment_aims(built: PickBuilt, context) -> dict:
    """At a stop: the tool's pose, and what every segment aims at now (position, rotation)."""
    station = built.station
    plant = station.plant
    pc = plant.GetMyContextFromRoot(context)
    tool = plant.GetFrameByName("fingertip_center", station.gripper).CalcPoseInWorld(pc)
    source = built.part_system()  # what the targets read: the estimates with a camera
    sc = source.GetMyContextFromRoot(context)
    tc = built.targets.GetMyContextFromRoot(context)
    latched = tc.get_discrete_state(0).get_value().copy()
    parts = [(source.GetOutputPort(f"part_{k}_pose").Eval(sc).copy(),
              source.GetOutputPort(f"part_{k}_rotation").Eval(sc).copy())
             for k in range(len(station.parts))]
    return {"tool": (tool.translation().copy(), tool.rotation().matrix().copy()), "parts": parts,
            "latched": latched}
