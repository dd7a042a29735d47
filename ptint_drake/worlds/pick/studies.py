"""The pick world's parts of the studies and of ``ptint run``'s lines: what ``robust`` draws for a
sample and keeps of it, a ``sweep`` point, why ``tune`` does not search a pick, the lines
``ptint run`` prints (each a hook of ``worlds.base.World``), and ``ptint bench --floors``'s
replayed-arm floor (``FloorReplay``)."""

from __future__ import annotations

import copy
import re
import sys
from collections import Counter

import numpy as np
from pydrake.systems.controllers import PidController
from pydrake.systems.framework import DiagramBuilder, EventStatus
from pydrake.systems.primitives import Adder, LogVectorOutput, Saturation, TrajectorySource
from pydrake.trajectories import PiecewisePolynomial

from ptint_drake.config.pick import PHASES
from ptint_drake.robot.mass_scaling import scale_in_context
from ptint_drake.worlds.base import advance_over_stops, new_simulator
from ptint_drake.worlds.pick.hold_limit import holdable
from ptint_drake.worlds.pick.line.robust import line_row, line_sample
from ptint_drake.worlds.pick.placement import placed_parts
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.run import pick_simulator
from ptint_drake.worlds.pick.station import MakePickStation


def mm_text(value) -> str:
    """A length in m as mm text ("n/a" when there is none)."""
    return "n/a" if value is None else f"{value * 1e3:.4g} mm"


def _camera_errors(measurement, u) -> dict:
    """An rgbd camera's calibration error (``camera_xyz_error`` per axis, m; ``camera_rpy_error``
    per axis, deg) and depth-noise scale (``depth_noise_scale``, ×) of this sample, drawn by ``u``."""
    camera = measurement.camera
    if measurement.sensor != "rgbd" or camera is None:
        return {}
    camera.pose_error = [float(v) for v in np.r_[u("camera_xyz_error", 3), u("camera_rpy_error", 3)]]
    camera.depth_noise_scale *= float(u("depth_noise_scale"))
    return {"camera_pose_error": list(camera.pose_error),
            "depth_noise_scale": float(camera.depth_noise_scale)}


def _random_placement(pick, u) -> None:
    """An rgbd pick's parts placed at random: yaw any, lateral in ``u.bounds("placed_lateral")``
    clipped to the part's belt's half width (drawn from the sample's seed by ``placement``; the
    plan is not told)."""
    low, high = u.bounds("placed_lateral")
    belts = {b.name: b for b in pick.belts}
    for part in pick.parts:
        half = belts[part.belt].width / 2
        part.yaw_deg = "random"
        part.lateral = [max(low, -half), min(high, half)]


def robust_sample(scenario, name: str, seed: int, u):
    """A pick scenario's sample, drawn in this order (so that the ``mild`` preset, whose last two
    ranges are [0, 0], draws what the study drew before they existed): the arm's link masses; every
    part's mass and friction; every belt's speed (×); every task's close-command jitter (s, added
    to the close's time: ``close_delay``); every part's lateral offset on its belt (m, ``lateral``,
    clipped to the belt's half width); with an rgbd camera, last, its calibration error and depth
    noise (``_camera_errors``) and every part's random placement (``_random_placement``).  A line
    draws per part of its pool instead (``line.robust``)."""
    if scenario.pick.line is not None:
        return line_sample(scenario, name, seed, u)
    scenario.plant.mass_scale = float(u("mass"))
    pick = scenario.pick
    for part in pick.parts:
        part.mass, part.friction = float(u("part_mass")), float(u("part_friction"))
    for belt in pick.belts:
        belt.speed *= float(u("belt_speed"))
    for task in pick.tasks:
        task.close_delay += float(u("close_jitter"))
    belts = {b.name: b for b in pick.belts}
    for part in pick.parts:
        half = belts[part.belt].width / 2 if part.belt in belts else 0.0
        shift = float(u("part_lateral"))
        if not isinstance(part.lateral, list):  # a [min, max] range is drawn from measurement.seed
            part.lateral = float(np.clip(part.lateral + shift, -half, half))
    camera = {}
    if scenario.measurement is not None:  # a camera's noise and the random placement: this sample's
        scenario.measurement.seed = seed
        camera = _camera_errors(scenario.measurement, u)
        if scenario.measurement.sensor == "rgbd":
            _random_placement(pick, u)
        placed = placed_parts(pick.parts, seed)
        camera |= {"placed_yaw_deg": [p.yaw_deg for p in placed],
                   "placed_lateral": [p.lateral for p in placed], "placed_offset": [p.offset for p in placed]}
    scenario.name = f"{name}_seed{seed}"
    params = {"mass_scale": scenario.plant.mass_scale, "part_mass": [p.mass for p in pick.parts],
              "part_friction": [p.friction for p in pick.parts],
              "belt_speed": [b.speed for b in pick.belts],
              "close_delay": [t.close_delay for t in pick.tasks],
              "part_lateral": [p.lateral for p in pick.parts],
              "holdable": [holdable(pick, t.part) for t in pick.tasks]}
    return scenario, params | camera


def robust_row(seed: int, params: dict, m: dict) -> dict:
    """What a pick sample keeps of its metrics: the picks, the reasons (a line's: its parts,
    ``line.robust``)."""
    if "line" in m:
        return line_row(seed, params, m)
    e_tf = [s["e_tf_norm"] for s in m["segments"]]
    keys = ("part", "grasped", "placed", "place_error_mm", "place_error_deg", "slip_mm", "t_grasp",
            "collision")
    return {"seed": seed, "params": params, "ok": m["status"] == "ok", "status": m["status"],
            "e_tf": e_tf,
            "e_tf_max": max((v for v in e_tf if v is not None), default=None),
            "picks": [{k: p.get(k) for k in keys} for p in m["picks"]],
            "reasons": m["reasons"], "realtime_factor": m["sim"]["realtime_factor"],
            "warnings": m["warnings"]}


_NUMBER = re.compile(r"(?<![\w.])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?(?!\w)")


def failure_reason(text: str) -> str:
    """A verdict's reason or a sample's error as a reason to count: without the pick's index
    (``pick 2: dropped`` → ``dropped``), list indices as ``[k]``, other numbers as ``#``."""
    text = re.sub(r"^pick \d+: ", "", text.strip())
    text = re.sub(r"\[\d+\]", "[k]", text)
    text = re.sub(r"\[[^\]]*\d[^\]]*\]", "[…]", text)
    return _NUMBER.sub("#", text)[:160]


def _pick_oks(row: dict) -> list[bool]:
    """Per pick of a sample: placed, with no collision and no reason of the verdict naming it."""
    named = {int(m.group(1)) for text in row.get("reasons") or [] if (m := re.match(r"pick (\d+):", text))}
    return [bool(p.get("placed")) and not p.get("collision") and k not in named
            for k, p in enumerate(row.get("picks", []))]


def picks_ok(row: dict) -> int:
    """How many of a sample's picks succeeded: placed, with no collision and no reason of the
    verdict naming the pick (``pick k: late grasp`` fails pick k even if it was placed)."""
    return sum(_pick_oks(row))


def holdable_counts(rows: list) -> dict:
    """``cannot_be_held`` (picks whose part no grasp could lift: ``hold_limit``, judged from the
    drawn truth) and ``pick_success_rate_holdable`` (picks that succeeded among the others);
    {} for rows without the judgement (studies written before it)."""
    if not rows or any("holdable" not in r.get("params", {}) for r in rows):
        return {}
    can = cannot = ok = 0
    for r in rows:
        flags = r["params"]["holdable"]
        oks = _pick_oks(r) or [False] * len(flags)  # a sample that could not run placed none
        can, cannot = can + sum(flags), cannot + len(flags) - sum(flags)
        ok += sum(o for o, h in zip(oks, flags) if h)
    return {"cannot_be_held": cannot, "pick_success_rate_holdable": ok / can if can else 0.0}


def robust_summary(rows: list) -> dict:
    """``pick_success_rate`` (picks that succeeded, ``picks_ok``, over all parts, a sample that
    could not run placing none), ``failures_by_reason`` ({reason: count}, ``failure_reason``:
    each reason of a sample's verdict, each sample's error; most frequent first; every
    ``collision with <bodies>`` under the one key ``collision``), ``collisions_by_body`` ({body:
    how many of those collisions touched it}) and ``placed_with_collision`` (parts placed by a
    pick that collided: the collisions among the placed parts) of a pick study; {} otherwise."""
    if not any("picks" in r or "part_mass" in r.get("params", {}) for r in rows):
        return {}
    parts = sum(len(r["params"]["part_mass"]) for r in rows)
    ok = sum(picks_ok(r) for r in rows)
    reasons, bodies = Counter(), Counter()
    for r in rows:
        texts = r.get("reasons") or ([f"error: {r['error']}"] if r.get("error") else [])
        for text in texts:
            code = failure_reason(text)
            if code.startswith(COLLISION):  # one key, whatever was touched: the bodies beneath
                touched = code[len(COLLISION):].removeprefix(" with ")
                bodies.update(b.strip() for b in touched.split(",") if b.strip())
                code = COLLISION
            reasons[code] += 1
    touched = sum(1 for r in rows for p in r.get("picks", []) if p.get("placed") and p.get("collision"))
    return {"pick_success_rate": ok / parts if parts else 0.0, **holdable_counts(rows),
            "failures_by_reason": _most_first(reasons), "collisions_by_body": _most_first(bodies),
            "placed_with_collision": touched}


COLLISION = "collision"  # failures_by_reason's key of every ``collision with <bodies>``


def _most_first(counts: Counter) -> dict:
    return dict(sorted(counts.items(), key=lambda kv: (-kv[1], kv[0])))


def sweep_point(row: dict, scenario, beta: float, tf: float, simulate, validate, schedule_end) -> dict:
    """A pick scenario's grid point (module docstring)."""

    for task in scenario.pick.tasks:
        for phase in PHASES:
            getattr(task, phase).beta = beta
        task.approach.tf = tf
    try:
        validate(scenario)
        scenario.duration = max(scenario.duration, schedule_end(scenario) + 0.5)
        result = simulate(scenario)
    except (ValueError, RuntimeError) as exc:  # a ScenarioError is a ValueError
        return row | {"error": " ".join(str(exc).split())[:200], "ok": False}
    m = result.metrics
    e_tf = [s["e_tf_norm"] for s in m["segments"] if s["e_tf_norm"] is not None]
    return row | {"e0": max((s["e0_norm"] or 0.0) for s in m["segments"]), "e_tf": max(e_tf, default=None),
                  "peak_torque": float(np.max(m["torque_peak"])),
                  "peak_torque_after_startup": float(np.max(m["torque_peak_after_startup"])),
                  "realtime_factor": m["sim"]["realtime_factor"], "steps": m["sim"]["steps"],
                  "ok": m["status"] == "ok"}


def report(scenario, metrics: dict, out) -> int:
    """A pick scenario's output: one line per segment and per pick, the verdict (exit 1 unless ok)."""
    for i, seg in enumerate(metrics["segments"]):
        print(f"{scenario.name} segment {i} (task {seg['task']} {seg['phase']}): "
              f"e0 = {mm_text(seg['e0_norm'])}, "
              f"e(tf) = {mm_text(seg['e_tf_norm'])}, {seg['e_rot_tf_deg'] or 0.0:.2f}°")
    for k, p in enumerate(metrics["picks"]):
        grasp = "never" if p["t_grasp"] is None else \
            f"{p['t_grasp']:.3f} s (prescribed {p['t_grasp_prescribed']:.3f} s)"
        into = (f"bin {p['bin']}" if "bin" in p else f"belt {p['belt']}" if "belt" in p
                else f"slot {p['slot']}")
        place = (f"{'placed' if p['placed'] else 'NOT placed'} {p['place_error_mm']:.2f} mm "
                 f"{p['place_error_deg']:.2f}° from its slot" if "bin" not in p and "belt" not in p
                 else ("in the bin" if p["placed"] else "NOT in the bin") if "bin" in p
                 else (f"on the belt, {p['place_error_mm']:.2f} mm from its riding point" if p["placed"]
                       else "NOT on the belt"))
        print(f"{scenario.name} pick {k} ({p['part']} → {into}): grasped at {grasp}, {place}, "
              f"slip {p['slip_mm'] or 0.0:.2f} mm, "
              f"contact grip {p['peak_grip_force_N']:.1f} N peak, {p.get('grip_force_N') or 0.0:.1f} N at "
              f"the lift; {p.get('attempts', 1)} "
              f"attempt{'s' if p.get('attempts', 1) != 1 else ''}, {p.get('state_at_place')} at the place"
              + (f", COLLISION with {', '.join(p['collision_with'])}" if p.get("collision_with")
                 else ", COLLISION before the close" if p["collision"] else ""))
    sim = metrics["sim"]
    print(f"realtime factor {sim['realtime_factor']:.2f} end to end ({sim['contact_approximation']}, "
          f"{sim['contact_model']} contact, {1e3 * sim['plant_time_step']:g} ms plant); wrote {out}/")
    if metrics["status"] == "failed":
        print(f"ptint: error: run failed: {metrics['failure']['message']}", file=sys.stderr)
        return 1
    if metrics["status"] == "missed":
        print(f"{scenario.name}: MISSED ({'; '.join(metrics['reasons'])})")
        return 1
    line = metrics.get("line")
    none = line is not None and not line["released"]  # (a line's draw that released no part)
    print(f"{scenario.name}: ok ({'no part arrived' if none else 'every part placed'})")
    return 0


# ``ptint bench --floors`` on a pick scenario: the run beside its replayed-arm floor.

FLOOR_KP = 100.0  # N·m/rad per joint: the replay's PD on the logged [q; v] (the logged torque fed forward)
FLOOR_KD = 2.0  # N·m·s/rad per joint


def _samples(times, values) -> tuple:
    """(times, values) with one sample per time, as the plant's discrete update at that time took
    it: of equal times the first (a later one follows an update, e.g. ``AdvanceTo`` a reached
    stop), of times within 1 ns the last (the step to a stop a hair before a sample time)."""
    ts, vs = [], []
    for t, v in zip(times, values):
        t = float(t)
        if ts and t == ts[-1]:
            continue
        if ts and t - ts[-1] < 1e-9:
            ts.pop(), vs.pop()
        ts.append(t), vs.append(np.atleast_1d(np.asarray(v, dtype=float)))
    return np.array(ts), np.array(vs)


def _hold(times, values, end: float) -> PiecewisePolynomial:
    """A zero-order hold through the samples (``_samples``), held to ``end`` (and a second on)."""
    ts, vs = _samples(times, values)
    ts, vs = np.r_[ts, max(end, ts[-1] + 1.0)], np.vstack([vs, vs[-1:]])
    return PiecewisePolynomial.ZeroOrderHold(ts, vs.T)


class FloorRun:
    """The pick run's floor (``FloorReplay.floor``): the same station (arm, gripper and its driver,
    belts, parts, tray, the same plant settings and start) driven by Drake's C++ systems alone —
    a ``TrajectorySource`` replaying the run's arm torques (a zero-order hold of what the plant
    received at each step) added to a ``PidController`` (PD, no I) on the run's [q; v] (a
    first-order hold), through the arm's effort limits (``Saturation``), and a ``TrajectorySource``
    replaying the gripper's commands — simulated with the run's integrator and stops.  Replaying
    what the run computed, the arm follows the run's trajectory, the fingers close at the run's
    times and the contacts are the run's; only the controller, the targets, the probe and the
    loggers (the run's Python) are gone.  ``log``: log the arm's [q; v] every step."""

    advance_at_reached_stops = True

    def __init__(self, scenario, recording: dict, stops: list, log: bool = False):
        builder = DiagramBuilder()
        self.scenario, self._stops = scenario, stops
        self.station = MakePickStation(world_config(scenario))
        st = builder.AddNamedSystem("pick_station", self.station.diagram)
        t, x = _samples(recording["t"], recording["state"])
        end = scenario.duration
        nq = x.shape[1] // 2
        desired = builder.AddNamedSystem("logged_state", TrajectorySource(
            PiecewisePolynomial.FirstOrderHold(t, x.T)))
        torque = builder.AddNamedSystem("logged_torque", TrajectorySource(
            _hold(recording["t"], recording["torque"], end)))
        pd = builder.AddNamedSystem("pd", PidController(np.full(nq, FLOOR_KP), np.zeros(nq),
                                                         np.full(nq, FLOOR_KD)))
        adder = builder.AddNamedSystem("feedforward_plus_pd", Adder(2, nq))
        limits = recording["limits"]
        saturation = builder.AddNamedSystem("saturation", Saturation(-limits, limits))
        command_times, command_values = zip(*recording["commands"])
        gripper = builder.AddNamedSystem("logged_gripper_command", TrajectorySource(
            _hold(command_times, command_values, end)))
        builder.Connect(st.GetOutputPort("state"), pd.get_input_port_estimated_state())
        builder.Connect(desired.get_output_port(), pd.get_input_port_desired_state())
        builder.Connect(torque.get_output_port(), adder.get_input_port(0))
        builder.Connect(pd.get_output_port_control(), adder.get_input_port(1))
        builder.Connect(adder.get_output_port(), saturation.get_input_port())
        builder.Connect(saturation.get_output_port(), st.GetInputPort("actuation"))
        builder.Connect(gripper.get_output_port(), st.GetInputPort("gripper_command"))
        period = scenario.controller.control_period
        self.logger = LogVectorOutput(st.GetOutputPort("state"), builder, period) if log else None
        self.diagram = builder.Build()
        self.diagram.set_name("pick_floor")
        self.simulator_config = pick_simulator(scenario)

    def initialize(self, context) -> None:
        """The run's start (``world.PickRun.initialize``): scaled arm masses, belts and parts moving."""
        plant = self.station.plant
        plant_context = plant.GetMyMutableContextFromRoot(context)
        scale_in_context(plant, plant_context, self.station.arm, self.scenario.plant.mass_scale)
        self.station.start_running(plant_context)

    def stops(self) -> list:
        return list(self._stops)

    def at_stop(self, context, t: float) -> None:
        """Nothing is measured on the floor."""


class FloorReplay:
    """A pick scenario's run and its floor, for ``studies.benchmark``: ``run()`` is a fresh run
    of the scenario (``make_run(scenario)``, a ``worlds.base.WorldRun``); ``record()`` simulates
    one run with a monitor that keeps, after every step, the arm's [q; v] and the torque the plant
    takes at that time (the saturated controller output), and the plan's gripper commands;
    ``floor(log)`` is the ``FloorRun`` replaying that recording."""

    def __init__(self, scenario, make_run):
        self.scenario, self._make_run = scenario, make_run
        self.recording: dict = {}

    def run(self):
        return self._make_run(copy.deepcopy(self.scenario))

    def record(self) -> dict:
        run = self.run()
        built = run.built
        station = built.diagram.GetSubsystemByName("pick_station")
        saturation = built.diagram.GetSubsystemByName("saturation")
        ts, xs, taus = [], [], []

        def keep(context):
            ts.append(context.get_time())
            xs.append(station.GetOutputPort("state").Eval(station.GetMyContextFromRoot(context)).copy())
            taus.append(saturation.get_output_port().Eval(saturation.GetMyContextFromRoot(context)).copy())
            return EventStatus.Succeeded()

        simulator = new_simulator(run.diagram, config=run.simulator_config)
        run.initialize(simulator.get_mutable_context())
        simulator.set_monitor(keep)
        advance_over_stops(simulator, run, self.scenario, monitor=keep)  # the runner's own loop
        self.recording = {"t": np.array(ts), "state": np.array(xs), "torque": np.array(taus),
                          "commands": list(built.plan.commands), "limits": np.asarray(built.limits),
                          "stops": run.stops()}
        return self.recording

    def scenario_integrator(self) -> str:
        """The run's integrator settings, in words."""
        c = pick_simulator(self.scenario)
        return (f"{c.integration_scheme}, max step {c.max_step_size:g} s"
                + (f", accuracy {c.accuracy:g}" if c.use_error_control else ", fixed step"))

    def floor(self, log: bool = False) -> FloorRun:
        if not self.recording:
            self.record()
        return FloorRun(copy.deepcopy(self.scenario), self.recording, self.recording["stops"], log)
