"""A world of the tests' own, as a user writes one (``world: {type: "touch_world:TouchWorld"}``):
the gripper's tool point touches a fixed point at the prescribed time and stays there.

It uses only what a world's author reaches from outside the package's worlds: the protocol
(``worlds.base``), the simulated arm (``robot.make_plant``), the controller slot
(``controllers.AddControllerTo`` with a ``TargetView`` of analytic objects), the interceptor's
segments (``systems.task.schedule``), a target law (``systems.task.targets.LinearTarget`` at rest) and the
segment verdict (``metrics.segments_reasons``).  Its station is the bare plant: no scene graph,
no contact, continuous unless the scenario's ``multibody`` makes it discrete (as ``ptint
hardware`` does).  ``params``: ``point`` (m, world frame), ``tf`` (s), ``beta``.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.controllers import AddControllerTo, TargetView
from ptint_drake.robot.plant import make_plant
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.targets import LinearTarget
from ptint_drake.verdict.metrics import segments_reasons
from ptint_drake.worlds.base import World, WorldRun


def _settings(scenario) -> tuple[np.ndarray, float, float]:
    p = scenario.world.params
    return np.asarray(p["point"], float), float(p.get("tf", 1.0)), float(p.get("beta", 0.75))


class TouchRun(WorldRun):
    """The bare plant, the controller in its slot aiming at the point, a log of the arm's state."""

    def __init__(self, scenario, world: "TouchWorld", log: bool = True):
        self.scenario = scenario
        self.point, tf, _ = _settings(scenario)
        self.schedule, self.targets = world.schedule(scenario), world.objects(scenario)
        self.tf = tf
        builder = DiagramBuilder()
        self.plant = plant = builder.AddSystem(make_plant(scenario))
        self.frame = plant.GetFrameByName(scenario.robot.end_effector)
        self.controller = AddControllerTo(
            builder, plant=plant, frame=self.frame, schedule=self.schedule,
            state=plant.get_state_output_port(), actuation=plant.get_actuation_input_port(),
            scenario=scenario, target=TargetView(builder, None, scenario, self.schedule, self.targets),
            targets=self.targets)
        self.logger = LogVectorOutput(plant.get_state_output_port(), builder, publish_period=0.0)
        self.diagram = builder.Build()
        self.simulator_config = scenario.simulator
        self.plant_time_step = plant.time_step()
        self._at: dict = {}

    def initialize(self, context) -> None:
        plant_context = self.plant.GetMyMutableContextFromRoot(context)
        self.plant.SetPositions(plant_context, np.radians(self.scenario.robot.initial_q_deg))

    def _tool(self, plant_context) -> tuple[np.ndarray, np.ndarray]:
        x = self.plant.CalcPointsPositions(plant_context, self.frame, np.zeros(3), self.plant.world_frame())
        v = self.frame.CalcSpatialVelocityInWorld(plant_context).translational()
        return x[:, 0], v

    def stops(self) -> list[float]:
        return sorted({0.0, 0.5 * self.tf, self.tf, self.scenario.duration})

    def at_stop(self, context, t: float) -> None:
        self._at[t] = self._tool(self.plant.GetMyContextFromRoot(context))

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        log = self.logger.FindLog(context)
        t, xv = log.sample_times(), log.data().T
        nq = self.plant.num_positions()
        scratch = self.plant.CreateDefaultContext()
        hold = 0.0
        for k in np.nonzero(t >= self.tf)[0]:
            self.plant.SetPositionsAndVelocities(scratch, xv[k])
            hold = max(hold, float(np.linalg.norm(self._tool(scratch)[0] - self.point)))
        err = {s: float(np.linalg.norm(self._at[s][0] - self.point)) for s in self._at}
        segment = {"start": 0.0, "tf": self.tf, "beta": self.schedule.segments[0].beta,
                   "e0_norm": err[0.0], "e_half_norm": err[0.5 * self.tf], "e_tf_norm": err[self.tf],
                   "edot_tf_norm": float(np.linalg.norm(self._at[self.tf][1])), "e_hold_max_norm": hold}
        metrics = {"scenario": self.scenario.name, "duration": self.scenario.duration,
                   "segments": [segment], "touch": {"point": self.point.tolist(), "miss_m": err[self.tf]}}
        series = {"t": t, "q": xv[:, :nq], "v": xv[:, nq:]}
        return metrics, series, []


class TouchWorld(World):
    """Touch a fixed point with the gripper at the prescribed time (module docstring)."""

    name = "touch"
    summary = "the gripper touches a fixed point at the prescribed time (a test plugin)"

    def schedule(self, scenario) -> Schedule:
        _, tf, beta = _settings(scenario)
        return Schedule([Segment(0.0, tf, beta)])

    def objects(self, scenario) -> list:
        point, _, _ = _settings(scenario)
        return [LinearTarget(point, np.zeros(3))]

    def prepare(self, scenario, log: bool = True) -> TouchRun:
        return TouchRun(scenario, self, log)

    def reasons(self, metrics: dict, criteria) -> list:
        return segments_reasons(metrics, criteria)
