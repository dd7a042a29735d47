"""``ptint bench --arms``: each bundled arm's curve realtime factor beside a plain pydrake loop on
the same arm with the same integrator, and the bound the package holds to (issue 45).

The curves: the paper's ``curve_b075_tf15`` on ``rvm1``, the same on ``rvm1_5dof`` and
``rvm1_6dof`` (position task, their start angles, ``null_space_damping`` 10 as the industrial arms':
without it their spare joints leave their ranges), and ``curve_iiwa14``, ``curve_panda``,
``curve_ur5e`` as bundled.

**The package's run**: the scenario's world builds its diagram (``World.prepare``, without the
per-step loggers) and the runner's own loop simulates it (``Initialize``, then ``AdvanceTo`` over
the world's stops: ``worlds.base.advance_over_stops``) with the scenario's ``simulator`` settings.

**The plain loop** is what a user writes in pydrake alone: a ``DiagramBuilder`` with a continuous
``MultibodyPlant`` parsed from the same model file (nothing else: no saturation block, no object
system, no loggers) and one Python ``LeafSystem`` (``PlainTaskPD``) that reads [q; v] and, at every
derivative evaluation, sets a plant context of its own, asks Drake for the tool point's position,
its translational Jacobian and the gravity torques, and outputs gravity compensation plus a
Jacobian-transpose PD on the same sinusoid (x_r = c + a sin(ωt + φ), evaluated in numpy) minus a
joint damping, clipped to the effort limits.  No TBG, sliding surface, schedule or compiled kernel.
It runs in a plain ``Simulator`` with the same ``SimulatorConfig`` (integration scheme, accuracy,
step cap) from the same start angles at rest.

**Timing**: one warm-up of each, then ``pairs`` alternated pairs (package first, then plain first,
…); each run's ``AdvanceTo`` wall and process-CPU seconds per simulated second.  Per arm:
``package_rtf`` and ``plain_rtf`` (simulated s / wall s, median), their derivative evaluations and
µs per evaluation, ``ratio`` = the median over pairs of CPU(plain) / CPU(package) — the package's
realtime factor as a fraction of the plain loop's, on CPU time so that a busy machine counts
less — its range, the package's e(tf) and the plain loop's |x_r − x| at tf (it is a working
controller, not a do-nothing).  ``BOUND``: the ratio the package holds to on every arm
(``holds``: whether it did in this run).
"""

from __future__ import annotations

import statistics
import time

import numpy as np
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.systems.framework import DiagramBuilder, LeafSystem

from ptint_drake.robot.plant import resolve_model
from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text
from ptint_drake.simulation import simulate
from ptint_drake.worlds.base import advance_over_stops, new_simulator
from ptint_drake.worlds.registry import world_of
from ptint_drake.worlds.runner import make_simulator

# arm → (scenario, overrides): each arm's curve
ARM_CURVES = {
    "rvm1": ("curve_b075_tf15", []),
    "rvm1_5dof": ("curve_b075_tf15", ["robot.model=rvm1_5dof",
                                      "robot.initial_q_deg=[22.5, 45.0, 30.0, 0.0, 0.0]",
                                      "controller.null_space_damping=10.0"]),
    "rvm1_6dof": ("curve_b075_tf15", ["robot.model=rvm1_6dof",
                                      "robot.initial_q_deg=[22.5, 45.0, 30.0, 0.0, -45.0, 0.0]",
                                      "controller.null_space_damping=10.0"]),
    "iiwa14": ("curve_iiwa14", []),
    "panda": ("curve_panda", []),
    "ur5e": ("curve_ur5e", []),
}
# The package's realtime factor is at least this fraction of the plain loop's on every arm (CPU
# time, median of the pairs).  Measured (`ptint bench --arms`, 5 pairs, Drake 1.58, Python 3.13,
# 2-core machine at load ~6, two runs; docs/speed.md): 0.86-0.98 on the 5- to 7-joint arms,
# 2.46-2.57 on the 3-joint rvm1 (its closed-form kinematics); single pairs down to 0.64, so the
# bound is on the median and leaves room for a busier machine.
BOUND = 0.7
# the plain loop's gains: task-space stiffness (N/m), damping (N·s/m), joint damping (N·m·s/rad)
PLAIN_KP, PLAIN_KD, PLAIN_JOINT_DAMPING = 2000.0, 150.0, 1.0


class PlainTaskPD(LeafSystem):
    """The plain loop's controller (module docstring): gravity compensation + Jacobian-transpose
    PD on the sinusoid ``c + a sin(ωt + φ)`` at frame ``frame_name``'s origin, minus a joint damping,
    clipped to ``limits``; a plant context of its own, set from the state input at every call."""

    def __init__(self, plant: MultibodyPlant, frame_name: str, sinusoid, limits: np.ndarray):
        super().__init__()
        self._plant, self._context = plant, plant.CreateDefaultContext()
        self._frame, self._world = plant.GetFrameByName(frame_name), plant.world_frame()
        self._c, self._a = np.asarray(sinusoid.center), np.asarray(sinusoid.amplitude)
        self._w, self._phi = float(sinusoid.omega), np.asarray(sinusoid.phase)
        self._limits, self._nq = limits, plant.num_positions()
        self._state = self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(), self._calc)

    def target(self, t: float) -> tuple:
        s = self._w * t + self._phi
        return self._c + self._a * np.sin(s), self._a * self._w * np.cos(s)

    def _calc(self, context, output) -> None:
        x = self._state.Eval(context)
        plant, ctx = self._plant, self._context
        plant.SetPositionsAndVelocities(ctx, x)
        p = plant.CalcPointsPositions(ctx, self._frame, np.zeros(3), self._world)[:, 0]
        J = plant.CalcJacobianTranslationalVelocity(ctx, JacobianWrtVariable.kV, self._frame, np.zeros(3),
                                                    self._world, self._world)
        v = x[self._nq:]
        x_r, v_r = self.target(context.get_time())
        force = PLAIN_KP * (x_r - p) + PLAIN_KD * (v_r - J @ v)
        tau = J.T @ force - plant.CalcGravityGeneralizedForces(ctx) - PLAIN_JOINT_DAMPING * v
        output.SetFromVector(np.clip(tau, -self._limits, self._limits))


def arm_scenario(arm: str):
    """The validated curve scenario of ``arm`` (``ARM_CURVES``)."""
    name, overrides = ARM_CURVES[arm]
    _, text = scenario_text(name)
    return parse_with_overrides(text, overrides or "{}", name)


def plain_loop(scenario):
    """(diagram, controller) of the plain loop (module docstring) on ``scenario``'s arm and curve."""
    builder = DiagramBuilder()
    plant = builder.AddSystem(MultibodyPlant(0.0))
    Parser(plant).AddModels(str(resolve_model(scenario.robot.model)))
    plant.Finalize()
    plant.SetDefaultPositions(np.radians(scenario.robot.initial_q_deg))
    # the controller's own copy: a plant inside a diagram cannot lend its context
    mirror = MultibodyPlant(0.0)
    Parser(mirror).AddModels(str(resolve_model(scenario.robot.model)))
    mirror.Finalize()
    limits = np.array([mirror.get_joint_actuator(i).effort_limit() for i in mirror.GetJointActuatorIndices()])
    controller = builder.AddSystem(PlainTaskPD(mirror, scenario.robot.end_effector,
                                               scenario.interceptions[0].target.sinusoid, limits))
    builder.Connect(plant.get_state_output_port(), controller.get_input_port())
    builder.Connect(controller.get_output_port(), plant.get_actuation_input_port())
    return builder.Build(), controller, plant


def _plain_once(scenario) -> dict:
    diagram, controller, plant = plain_loop(scenario)
    simulator = new_simulator(diagram, config=scenario.simulator)
    simulator.Initialize()
    cpu0, wall0 = time.process_time(), time.perf_counter()
    simulator.AdvanceTo(scenario.duration)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    context = simulator.get_context()
    p = plant.CalcPointsPositions(plant.GetMyContextFromRoot(context), plant.GetFrameByName(
        scenario.robot.end_effector), np.zeros(3), plant.world_frame())[:, 0]
    x_r, _ = controller.target(context.get_time())
    integrator = simulator.get_integrator()
    return {"cpu": cpu, "wall": wall, "t": context.get_time(),
            "evaluations": int(integrator.get_num_derivative_evaluations()),
            "steps": int(integrator.get_num_steps_taken()), "error_end_m": float(np.linalg.norm(x_r - p))}


def _package_once(scenario) -> dict:
    run = world_of(scenario).prepare(scenario, log=False)
    simulator = make_simulator(run)
    run.initialize(simulator.get_mutable_context())
    cpu0, wall0 = time.process_time(), time.perf_counter()
    _, _, simulator, _ = advance_over_stops(simulator, run, scenario)
    cpu, wall = time.process_time() - cpu0, time.perf_counter() - wall0
    integrator = simulator.get_integrator()
    return {"cpu": cpu, "wall": wall, "t": simulator.get_context().get_time(),
            "evaluations": int(integrator.get_num_derivative_evaluations()),
            "steps": int(integrator.get_num_steps_taken())}


def _median(rows: list, key: str) -> float:
    return statistics.median(r[key] for r in rows)


def arm_row(arm: str, pairs: int = 3) -> dict:
    """One arm's entry of ``arms`` (module docstring): a whole ``simulate`` first (its e(tf),
    verdict and end-to-end realtime factor; also the warm-up), one plain warm-up, then ``pairs``
    alternated pairs."""
    scenario = arm_scenario(arm)
    metrics = simulate(scenario).metrics
    _plain_once(scenario)
    package, plain, ratios = [], [], []
    for i in range(pairs):
        if i % 2 == 0:
            a = _package_once(scenario)
            b = _plain_once(scenario)
        else:
            b = _plain_once(scenario)
            a = _package_once(scenario)
        package.append(a), plain.append(b), ratios.append(b["cpu"] / a["cpu"])
    rtf = lambda rows: round(_median([{"r": r["t"] / r["wall"]} for r in rows], "r"), 3)  # noqa: E731
    us = lambda rows: round(1e6 * _median(rows, "wall") / rows[0]["evaluations"], 2)  # noqa: E731
    ratio = statistics.median(ratios)
    return {"scenario": ARM_CURVES[arm][0], "overrides": ARM_CURVES[arm][1],
            "joints": len(scenario.robot.initial_q_deg),
            "integrator": {"scheme": scenario.simulator.integration_scheme,
                           "accuracy": scenario.simulator.accuracy,
                           "max_step_size": scenario.simulator.max_step_size},
            "status": metrics["status"], "e_tf_mm": round(1e3 * metrics["segments"][0]["e_tf_norm"], 4),
            "end_to_end_rtf": round(metrics["sim"]["realtime_factor"], 3),
            "package_rtf": rtf(package), "plain_rtf": rtf(plain),
            "package_evaluations": package[0]["evaluations"], "plain_evaluations": plain[0]["evaluations"],
            "package_us_per_evaluation": us(package), "plain_us_per_evaluation": us(plain),
            "plain_error_end_mm": round(1e3 * plain[0]["error_end_m"], 3),
            "ratio": round(ratio, 3), "ratio_range": [round(min(ratios), 3), round(max(ratios), 3)],
            "holds": ratio >= BOUND}


def arms(names=None, pairs: int = 3, progress=None) -> dict:
    """``ptint bench --arms``: every arm of ``ARM_CURVES`` (or ``names``), the bound and whether
    every arm held it."""
    rows = {}
    for arm in names or ARM_CURVES:
        if progress:
            progress(f"{arm} curve against the plain loop")
        rows[arm] = arm_row(arm, pairs)
    return {"bound": f"ratio >= {BOUND:g}: the package's realtime factor (CPU time) is at least "
                     f"{BOUND:g} x the plain pydrake loop's on the same arm and integrator",
            "plain_loop": "MultibodyPlant + a Python LeafSystem: gravity compensation + Jacobian-"
                          "transpose PD (studies.arm_bench)",
            "pairs": pairs, "arms": rows, "holds": all(r["holds"] for r in rows.values())}
