"""The world seam: what every world (the interception world, the pick world, …) implements, and
what a run hands back.

A *world* is one kind of scenario: which physical things are simulated, what the controller aims
at, how a run is measured and judged, and how it is drawn.  ``World`` is the protocol;
``worlds.registry`` lists the worlds and picks the one a scenario belongs to; ``worlds.runner``
owns the ``Simulator`` and its ``AdvanceTo`` loop for all of them.  A world builds a
``WorldRun`` for one scenario — the diagram and its handles — and the runner drives it:

1. ``pre_run_warnings()`` (checks before simulating; a ``ScenarioError`` stops the run);
2. ``simulator_config``, ``initialize(context)`` and ``monitor(progress)`` (the watchdog);
3. ``stops()``: the exact times ``AdvanceTo`` lands on; ``at_stop(context, t)`` after each; then
   ``replan(context, t)``: True when the world planned anew there (its ``diagram`` is new: the
   runner makes a new simulator and ``resume(new_context, old_context)`` carries the state), and
   ``stops()`` is read again;
4. ``finish(context, integrator)`` → (metrics, series, warnings after the run);
5. ``reasons(metrics, criteria)``: why it missed (the verdict), and ``sim_info`` extras.

Adding a world = one package under ``worlds/`` with a ``World`` subclass, plus one line in
``worlds.registry.WORLDS`` (docs/design.md).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Optional

import numpy as np
from pydrake.systems.analysis import ApplySimulatorConfig, Simulator

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.systems.task.schedule import Schedule
from ptint_drake.verdict.metrics import Reason

Progress = Optional[Callable[[float, float, int], None]]
# doubles of a pose tracker's report of one body: [p (3), v (3), R row-major (9), ω (3)] (m, m/s,
# rad/s; world frame), a station's ``tracked_poses`` port and the link's ``TRACKED_POSES`` channel
TRACKED_SIZE = 18
TRACKER_PORT = "tracked_poses"  # a station's port of its pose tracker's reports (``LinkPorts``)


def new_simulator(diagram, context=None, config=None) -> Simulator:
    """The package's one construction of a Drake ``Simulator``: of ``diagram`` (from ``context``,
    else the diagram's default context), with ``config`` (a ``SimulatorConfig``) applied when
    given.  Every run, study, floor and the drive's controller loop start here, so that what a
    simulator is set up with is decided in one place (``worlds.runner.make_simulator`` adds a
    world's own settings)."""
    simulator = Simulator(diagram) if context is None else Simulator(diagram, context)
    if config is not None:
        ApplySimulatorConfig(config, simulator)
    return simulator


@dataclass
class RunResult:
    """A finished run: its scenario, metrics (metrics.json's content) and logged series."""

    scenario: Scenario
    metrics: dict
    series: dict = field(repr=False)

    @property
    def failed(self) -> bool:
        return self.metrics.get("status") == "failed"

    @property
    def ok(self) -> bool:
        return self.metrics.get("status") == "ok"


@dataclass(frozen=True)
class LinkPorts:
    """A station's ports that cross ``ptint hardware``'s link beside the arm's (``World.link_ports``):
    a gripper (status out, command in; ``gripper_max_force`` N, the commands' limit); a pose
    tracker's reports of ``objects`` bodies, in the station's order (its ``tracked_poses`` port,
    ``TRACKED_SIZE`` doubles a body: [p, v, R row-major, ω]; 0 where a camera sees them: no
    tracker); and a depth camera (``camera``: its name, the station's ``depth_image`` port, one
    frame every 1 / ``camera_rate_hz`` s).  No truth port of a station crosses the link."""

    gripper_max_force: float
    objects: int
    camera: Optional[str] = None
    camera_rate_hz: float = 0.0


class WorldRun:
    """One scenario's diagram in one world, driven by ``worlds.runner.simulate`` (the module
    docstring gives the order of the calls).  Subclasses set ``diagram``, ``controller`` (the
    ``controllers.ControllerHandles``) and ``simulator_config``."""

    diagram: object
    controller: object
    simulator_config: object
    plant_time_step: float = 0.0
    # call ``AdvanceTo`` at a stop the context has reached already (t = 0): a discrete plant then
    # takes its update at that time before the stop is measured, as the pick world always did
    advance_at_reached_stops: bool = False

    def pre_run_warnings(self) -> list[str]:
        """Checks before the run: raise ``ScenarioError``, or return warnings."""
        return []

    def initialize(self, context) -> None:
        """Set what the diagram's defaults do not hold into the root ``context``."""

    def monitor(self, progress: Progress):
        """A ``Simulator`` monitor (the divergence watchdog), or None."""
        return None

    def watchdog_failure(self) -> Optional[dict]:
        """The monitor's failure ({time, message}) if it stopped the run."""
        return None

    def stops(self) -> list[float]:
        raise NotImplementedError

    def at_stop(self, context, t: float) -> None:
        """Record what is measured at the exact stop ``t``."""

    def replan(self, context, t: float) -> bool:
        """After ``at_stop``: True if the world replaced its ``diagram`` with a new plan from here."""
        return False

    def resume(self, new_context, old_context) -> None:
        """Set the new diagram's ``new_context`` from the replaced one's (after ``replan``)."""
        raise NotImplementedError

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        """(metrics, series, warnings known after the run)."""
        raise NotImplementedError

    def sim_info(self, integrator) -> dict:
        """This world's own entries of metrics.json's ``sim`` block."""
        return {}


class World:
    """A kind of scenario (module docstring).  ``block``: the scenario field that holds this
    world's settings (None: the world of scenarios that have no other world's block)."""

    name: str = ""
    block: Optional[str] = None
    summary: str = ""

    def validate(self, scenario: Scenario) -> None:
        """The checks of this world that need no robot model (``ScenarioError``)."""

    def schedule(self, scenario: Scenario) -> Schedule:
        """The interceptor's segments."""
        raise NotImplementedError

    def objects(self, scenario: Scenario) -> list:
        """The analytic motions of the objects the segments aim at ([] where none exist)."""
        return []

    def prepare(self, scenario: Scenario, log: bool = True) -> WorldRun:
        """The scenario's diagram and handles (``log``: with the per-step loggers)."""
        raise NotImplementedError

    def reasons(self, metrics: dict, criteria) -> list[Reason]:
        """Why a run that was not stopped missed (empty: ``ok``)."""
        raise NotImplementedError

    def figure_files(self, scenario: Scenario) -> list[str]:
        """The figure files ``ptint run`` writes (metrics.json's ``figures``)."""
        return []

    def view_tasks(self, scenario: Scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        """Arguments of ``draw_view`` for the run's figures and replay (picklable: a worker
        process draws each)."""
        return []

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        """Draw one view of ``view_tasks`` into ``stage``; returns its name."""
        raise NotImplementedError

    def simulator_config(self, scenario: Scenario):
        """The integrator settings this world runs ``scenario`` with when they are its own (None:
        the scenario's ``simulator``); ``ptint hardware`` and ``ptint drive`` keep them."""
        return None

    def controller_side(self, builder, scenario: Scenario, period: float):
        """``ptint drive``'s part of this world beyond the arm's state: systems added to
        ``builder`` that the controller aims with and their handles (``target``: its target
        view), fed from exported inputs of what the hardware side sends; None: the world's
        analytic targets suffice (``hardware.drive``)."""
        return None

    def own_plant_step(self, scenario: Scenario) -> Optional[float]:
        """The plant step (s) this world sets itself when ``scenario`` has no ``multibody`` block
        (None: the scenario decides, continuous without one); ``ptint hardware`` steps the plant
        at the control period and refuses a world whose own step differs."""
        return None

    def link_ports(self, scenario: Scenario) -> Optional["LinkPorts"]:
        """What this world's station sends and takes over ``ptint hardware``'s LCM link beside
        the arm's status and torque (None: the arm alone)."""
        return None

    def floor_diagram(self, scenario: Scenario, kind: str):
        """``ptint bench``'s floor diagrams (``studies.benchmark.floors``), or None."""
        return None

    # Hooks of the studies and the command line.  Each default below belongs to no world: it
    # reads only what every world has (the arm, its plant block, the verdict), or refuses in one
    # line what only some worlds can do; a world overrides what it does its own way.

    def report(self, scenario: Scenario, metrics: dict, out) -> Optional[int]:
        """Print ``ptint run``'s lines of a finished run and return the exit code, or None: the
        command's own lines (the verdict and its reasons, which every world's metrics carry)."""
        return None

    def tune_refusal(self, name: str) -> Optional[str]:
        """Why ``ptint tune`` cannot search this world's scenario ``name`` (None: it can).  The
        default refuses: tune reads the interceptor's segment verdicts of a world that says it can."""
        return (f"scenario: {name} belongs to the {self.name} world, which ptint tune does not "
                f"search (World.tune_refusal)")

    def compare_scenario(self, scenario: Scenario, controller: str) -> Scenario:
        """``ptint compare``'s scenario for ``controller`` (``controller.type`` already set): as
        it is, unless this world adapts it to a controller."""
        return scenario

    def compare_row(self, metrics: dict, series: dict) -> Optional[dict]:
        """``ptint compare``'s row of a finished run of this world, or None: the segments' own
        (``studies.compare.compare_run``)."""
        return None

    def robust_sample(self, scenario: Scenario, name: str, seed: int, u) -> tuple:
        """(scenario, params) of a ``robust`` sample drawn with ``u(key, size=None)`` (``u.rng``:
        the sample's generator): by default the arm's own deviations, which every world has —
        link masses, joint friction, Coulomb friction, a payload, a disturbance torque
        (``arm_sample``)."""
        return arm_sample(scenario, name, seed, u)

    def robust_row(self, seed: int, params: dict, metrics: dict) -> dict:
        """What a ``robust`` sample keeps of its metrics: by default the verdict and what every
        run reports, and per segment of the interceptor's schedule e(tf) and the hold."""
        return segment_row(seed, params, metrics)

    def robust_summary(self, rows: list) -> dict:
        """This world's entries of robust.json's summary."""
        return {}

    def sweep_point(self, row: dict, scenario: Scenario, beta: float, tf: float, simulate, validate
                    ) -> dict:
        """A ``sweep`` grid point (β of every segment, tf), simulated into ``row``.  The default
        refuses in one line (``ScenarioError``): a β × tf grid is a world's own."""
        raise ScenarioError(f"scenario: the {self.name} world has no β × tf grid to sweep "
                            f"(World.sweep_point)")


def arm_sample(scenario: Scenario, name: str, seed: int, u) -> tuple:
    """The arm's deviations of a ``robust`` sample, drawn in this order (a sample is reproduced
    from its seed): ``plant.mass_scale``, ``damping_scale``, ``coulomb`` (per joint),
    ``payload_kg``, the disturbance's amplitude (per joint), frequency (0.5-3 Hz), phase, step
    (± the disturbance range) and step time (``studies.robust``'s ranges).  A camera is a
    world's own: the interception world draws its noise and latency after these."""
    nv = len(scenario.robot.initial_q_deg)
    rng = u.rng
    p = scenario.plant
    p.mass_scale = float(u("mass"))
    p.damping_scale = float(u("friction"))
    p.coulomb = u("coulomb", nv).tolist()
    p.payload_kg = float(u("payload"))
    bound = u.bounds("disturbance")
    p.disturbance.amplitude = u("disturbance", nv).tolist()
    p.disturbance.frequency_hz = float(rng.uniform(0.5, 3.0))
    p.disturbance.phase = rng.uniform(0.0, 2 * np.pi, nv).tolist()
    p.disturbance.step = rng.uniform(-bound[1], bound[1], nv).tolist()
    p.disturbance.step_time = float(rng.uniform(0.0, scenario.duration))
    scenario.name = f"{name}_seed{seed}"
    params = {"mass_scale": p.mass_scale, "damping_scale": p.damping_scale, "coulomb": p.coulomb,
              "payload_kg": p.payload_kg, "disturbance_amplitude": p.disturbance.amplitude,
              "disturbance_frequency_hz": p.disturbance.frequency_hz,
              "disturbance_step": p.disturbance.step, "disturbance_step_time": p.disturbance.step_time}
    return scenario, params


def segment_row(seed: int, params: dict, m: dict) -> dict:
    """A ``robust`` row of any world's metrics: the verdict, and per segment e(tf) and the hold."""
    segments = m.get("segments", [])
    e_tf = [s.get("e_tf_norm") for s in segments]
    finished = bool(e_tf) and all(v is not None for v in e_tf)
    return {
        "seed": seed, "params": params,
        "ok": m["status"] == "ok",  # the one verdict (metrics.verdict, the scenario's criteria)
        "status": m["status"],
        "reasons": m.get("reasons", []),
        "e_tf": e_tf,
        "e_tf_max": max(e_tf) if finished else None,
        "hold_max": max(((s.get("e_hold_max_norm") or 0.0) for s in segments), default=None),
        "torque_peak": m.get("torque_peak"),
        "saturated_fraction": m.get("saturated_fraction"),
        "realtime_factor": m["sim"]["realtime_factor"],
        "warnings": m.get("warnings", []),
    }


def _failure(t: float, what: str, exc: BaseException) -> dict:
    detail = " ".join(str(exc).split())[:300]
    return {"time": t, "message": f"{what} at t = {t:.4f} s: {detail}"}


def advance_over_stops(simulator: Simulator, run: WorldRun, scenario: Scenario, progress: Progress = None,
                       monitor=None):
    """The one stop loop (the runner's, the benchmark's CPU timing, the pick floor's recording):
    ``Initialize``, then ``AdvanceTo`` every exact stop of ``run`` with ``at_stop`` after each;
    returns (failure or None, wall s of ``AdvanceTo``, the simulator of the end, steps taken by the
    simulators a replan replaced).  ``run.stops()`` is read again
    after each stop: a world that plans anew at a stop (``WorldRun.replan``) hands over a new
    diagram, which goes on from the old context's state in a new simulator."""
    context = simulator.get_mutable_context()
    failure, wall, done, steps_before = None, 0.0, None, 0
    simulator.Initialize()
    while True:
        upcoming = [t for t in run.stops() if done is None or t > done]
        if not upcoming:
            break
        t_stop = upcoming[0]
        if t_stop > context.get_time() or run.advance_at_reached_stops:
            t0 = time.perf_counter()
            try:
                simulator.AdvanceTo(t_stop)
            except RuntimeError as exc:  # e.g. a step-size collapse on a non-finite state
                failure = _failure(context.get_time(), "integration failed", exc)
            except Exception as exc:  # noqa: BLE001  (only a plugin's: the package's own are bugs)
                if not run.controller.plugin:
                    raise
                detail = " ".join(f"{type(exc).__name__}: {exc}".split())[:200]
                t = context.get_time()
                failure = {"time": t, "message": f"controller {scenario.controller.type} raised at "
                                                 f"t = {t:.4f} s: {detail}"}
            wall += time.perf_counter() - t0
        failure = failure or run.watchdog_failure()
        if failure is not None:
            break
        run.at_stop(context, t_stop)
        done = t_stop
        if run.replan(context, t_stop):
            steps_before += int(simulator.get_integrator().get_num_steps_taken())
            t0 = time.perf_counter()
            simulator = new_simulator(run.diagram, config=run.simulator_config)
            run.resume(simulator.get_mutable_context(), context)
            context = simulator.get_mutable_context()
            if monitor is not None:
                simulator.set_monitor(monitor)
            simulator.Initialize()
            wall += time.perf_counter() - t0
        if progress is not None:
            steps = steps_before + int(simulator.get_integrator().get_num_steps_taken())
            progress(context.get_time(), scenario.duration, steps)
    return failure, wall, simulator, steps_before
