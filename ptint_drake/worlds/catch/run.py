"""One catch run (issue 46): the station, the planner's target and close command, the controller
in its slot; started from the arm settled at its start pose (``settle``).

Planning (``revision_times``): from the end of the sensing, every ``catch.replan_every`` s, the
planner looks at the newest estimate.  Without a plan it tries to make one; a refused plan is
tried again at the next revision, until the ball (as estimated) has fallen below the floor
height or no time is left for a catch and its hold.  With a plan it re-checks it
(``Planner.holds``: the catch time's point re-predicted, still in reach in the time left) and
replaces it only when it no longer holds and a new one exists.  The last revision is
``catch.commit`` s before the catch time.  A new plan is a new diagram resumed from the old
state (``replan``/``resume``) whose schedule ends the running segment there and starts a new TBG
segment to the new catch time: the sliding surface captures s(t0) at a segment's start, so the
law's torque does not jump with the target (only the null-space term does, by its posture's
change: the catch segment's null-space posture is the plan's catch posture, so that the redundant
arm's self-motion leads to where the planner's IK found the catch within the joint limits).

Outcomes, each a truth test of the finished run (``outcome``), in this order:
``not reachable`` (no plan: the arm never moved); ``collision with <body>`` (the ball touched a
body of the arm); ``caught`` (at t_catch + ``held_for`` the ball's centre within ``outcome.HELD_RADIUS``
of the fingertip centre and the jaws stopped on it: the sensed opening between half the ball's
diameter and the diameter + ``GRIP_TOLERANCE``); ``slipped out`` (so held at t_catch + 0.1 s,
not at the end); ``late`` (the hand's tip more than ``LATE_RADIUS`` from the ball's centre at
t_catch); ``closed on nothing`` (the jaws closed below half the ball's diameter); else
``bounced off``.
"""

from __future__ import annotations

import dataclasses

import numpy as np
from pydrake.math import RigidTransform
from pydrake.multibody.math import SpatialVelocity
from pydrake.systems.analysis import SimulatorConfig
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import LogVectorOutput

from ptint_drake.controllers import AddControllerTo
from ptint_drake.robot.mass_scaling import scale_in_context
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.worlds.base import WorldRun
from ptint_drake.worlds.catch.ball import BALL_DIAMETER
from ptint_drake.worlds.catch.planner import FLOOR_Z, MIN_TF, Planner
from ptint_drake.worlds.catch.settle import SETTLE_STARTS, SETTLE_TF, snapshot, start_from
from ptint_drake.worlds.catch.station import TIP, AddCatchStation, arm_plant
from ptint_drake.worlds.catch.outcome import BallContacts, outcome
from ptint_drake.worlds.catch.target import CatchTarget, CatchTargetView, CloseCommand, close_time
from ptint_drake.worlds.catch.thrower import throw

_SETTLED: dict = {}


def settled(scenario):
    """The settled start of ``scenario``'s arm, controller and hand (``settle``), cached."""
    key = (tuple(scenario.robot.initial_q_deg), repr(scenario.controller), repr(scenario.catch.gripper))
    if key not in _SETTLED:
        _SETTLED[key] = snapshot(CatchRun(scenario, settling=True))
    return _SETTLED[key]


class CatchRun(WorldRun):
    """The catch of ``scenario.catch.throw`` (module docstring)."""

    def __init__(self, scenario, log: bool = True, settling: bool = False):
        self.scenario, c, self.settling = scenario, scenario.catch, settling
        self.arm = arm_plant()
        self.planner = Planner(self.arm, TIP, c.beta, c.match, c.match_time)
        self.q0 = np.radians(scenario.robot.initial_q_deg)
        self.x0, self.R0 = self.planner.tip(self.q0)
        self.throw = throw(c.throw, self.x0)
        self.parked = RigidTransform([self.throw.launch[0], self.throw.launch[1], -10.0])
        self.plan, self.plans, self.gave_up, self._replan = None, [], None, False
        self._pieces, self.touched, self.impact, self._at = [], {}, {}, {}
        self.simulator_config = SimulatorConfig(integration_scheme="explicit_euler", use_error_control=False,
                                                max_step_size=0.001)
        self.plant_time_step = c.time_step
        self._build()

    def schedule(self) -> Schedule:
        c = self.scenario.catch
        if self.settling:
            return Schedule([Segment(start, SETTLE_TF, c.beta) for start in SETTLE_STARTS])
        if self.plan is None:
            return Schedule([Segment(0.0, c.sensing, c.beta), Segment(c.sensing, 0.6, c.beta)])
        starts = sorted({0.0, c.sensing, *(p.t_plan for p in self.plans)})
        ends = starts[1:] + [self.plan.t_catch]
        segments = [Segment(a, _span(a, b), c.beta) for a, b in zip(starts, ends)]
        last = segments[-1]
        if c.final > 0.0 and last.tf >= 2.0 * c.final:
            segments[-1:] = [Segment(last.start, last.tf - c.final, c.beta),
                             Segment(last.end - c.final, c.final, c.beta)]
        return Schedule(segments)

    def _build(self) -> None:
        c, builder = self.scenario.catch, DiagramBuilder()
        self.station = st = AddCatchStation(builder, self.scenario)
        target = builder.AddNamedSystem("catch_target", CatchTarget(self.x0, self.R0, self.plan, c))
        builder.Connect(st.estimate, target.get_input_port())
        close = builder.AddNamedSystem("close_command", CloseCommand(
            c.gripper.initial_opening, close_time(self.plan, c.gripper.initial_opening, BALL_DIAMETER,
                                                  c.gripper.speed, c.close_lag)))
        builder.Connect(close.get_output_port(), st.command)
        view = CatchTargetView(target.GetOutputPort("target"), target.GetOutputPort("target_rotation"))
        self.controller = AddControllerTo(builder, plant=self.arm, frame=self.arm.GetFrameByName(TIP),
                                          schedule=self.schedule(), state=st.state, actuation=st.actuation,
                                          scenario=self._posture_scenario(), target=view, targets=[])
        self.logger = LogVectorOutput(st.plant.get_state_output_port(), builder, publish_period=0.001)
        self.estimate_log = LogVectorOutput(st.estimate, builder, publish_period=0.001)
        self.target_log = LogVectorOutput(target.GetOutputPort("target"), builder, publish_period=0.001)
        probe = builder.AddNamedSystem("ball_contacts", BallContacts(st.plant, st.ball, self.touched,
                                                                              self.impact))
        builder.Connect(st.plant.get_contact_results_output_port(), probe.get_input_port())
        self.diagram = builder.Build()

    def _posture_scenario(self):
        """The scenario whose controller's null-space posture is the plan's catch posture."""
        if self.plan is None:
            return self.scenario
        posture = np.degrees(self.plan.q[:7]).tolist()
        return dataclasses.replace(self.scenario, controller=dataclasses.replace(
            self.scenario.controller, null_space_posture_deg=posture))

    def initialize(self, context) -> None:
        start_from(settled(self.scenario), self, context)
        st = self.station
        pc = st.plant.GetMyMutableContextFromRoot(context)
        # a mass_xF plant variant: the simulated arm only (the planner and the law keep the nominal)
        scale_in_context(st.plant, pc, st.arm, self.scenario.plant.mass_scale)
        st.plant.SetFreeBodyPose(pc, st.ball, RigidTransform(np.array(self.throw.launch)))
        v0 = SpatialVelocity(np.zeros(3), np.array(self.throw.velocity))
        st.plant.SetFreeBodySpatialVelocity(pc, st.ball, v0)

    def revision_times(self) -> list[float]:
        """When the plan is made or revised (module docstring): from the sensing's end every
        ``replan_every`` s, until the commit time of a plan, else until the planner has nothing
        left to try or the run has no time left for a catch."""
        c = self.scenario.catch
        if self.plan is not None:
            end = self.plan.t_catch - c.commit
        else:
            end = self.gave_up if self.gave_up is not None else self.scenario.duration - c.held_for - MIN_TF
        n = int(np.floor((end - c.sensing) / c.replan_every + 1e-9)) + 1
        return [round(c.sensing + k * c.replan_every, 9) for k in range(max(n, 1))]

    def stops(self) -> list[float]:
        c = self.scenario.catch
        ends = [self.scenario.duration, *self.revision_times()]
        if self.plan is not None:
            ends += [self.plan.t_catch, self.plan.t_catch + 0.1, self.plan.t_catch + c.held_for]
        return sorted(set(t for t in ends if t <= self.scenario.duration))

    def at_stop(self, context, t: float) -> None:
        st = self.station
        pc = st.plant.GetMyContextFromRoot(context)
        tip = self.planner.tip(st.plant.GetPositions(pc, st.arm))[0]
        ball = st.plant.EvalBodyPoseInWorld(pc, st.ball).translation()
        self._at[t] = (float(np.linalg.norm(tip - ball)), float(np.sum(st.plant.GetPositions(pc, st.hand))))
        if self.gave_up is None and t in self.revision_times():
            estimate = np.asarray(st.estimate.Eval(st.estimator.GetMyContextFromRoot(context)))
            self._revise(estimate, t, st.plant.GetPositions(pc, st.arm))

    def _revise(self, estimate: np.ndarray, t: float, q: np.ndarray) -> None:
        """Plan, or revise the plan, at ``t`` (module docstring)."""
        if not np.any(estimate[3:6]):
            return
        if self.plan is not None and self.planner.holds(self.plan, estimate, t):
            return
        new = self.planner.plan(estimate, t, q, None if self.plan is None else self.plan.t_catch)
        if new is None:
            if self.plan is None and estimate[2] < FLOOR_Z and estimate[5] < 0.0:
                self.gave_up = t  # the ball is gone
            return
        self.plan, self._replan = new, True
        self.plans.append(new)

    def replan(self, context, t: float) -> bool:
        if not self._replan:
            return False
        self._replan = False
        self._pieces.append(tuple(log.FindLog(context) for log in self._logs()))
        self._build()
        return True

    def resume(self, new_context, old_context) -> None:
        new_context.SetTime(old_context.get_time())
        new_context.SetContinuousState(old_context.get_continuous_state_vector().CopyToVector())
        for i in range(old_context.num_discrete_state_groups()):
            new_context.SetDiscreteState(i, old_context.get_discrete_state(i).value())
        st = self.station  # the new diagram's: its plant's parameters start nominal again
        scale_in_context(st.plant, st.plant.GetMyMutableContextFromRoot(new_context), st.arm,
                         self.scenario.plant.mass_scale)

    def finish(self, context, integrator) -> tuple[dict, dict, list[str]]:
        pieces = self._pieces + [tuple(log.FindLog(context) for log in self._logs())]
        t = np.concatenate([logs[0].sample_times() for logs in pieces])
        x, estimate, target = (np.hstack([logs[i].data() for logs in pieces]).T for i in range(3))
        plan, name = self.plan, outcome(self.plan, self.touched, self._at)
        at_catch = self._at.get(plan.t_catch) if plan is not None else None
        metrics = {"scenario": self.scenario.name, "duration": self.scenario.duration, "segments": [],
                   "catch": {"throw": self.throw.seed, "outcome": name, "caught": name == "caught",
                             "t_catch": plan.t_catch if plan else None,
                             "tf_min": plan.tf_min if plan else None,
                             "plans": [_plan_row(p) for p in self.plans],
                             "catch_point": plan.point.tolist() if plan else None,
                             "catch_posture_deg": np.degrees(plan.q[:7]).tolist() if plan else None,
                             "error_at_catch_m": at_catch[0] if at_catch else None,
                             "peak_contact_force_n": max(self.touched.values(), default=0.0),
                             **self._impact(t, x),
                             **self._joint_speeds(x),
                             "touched": dict(sorted(self.touched.items()))}}
        return metrics, {"t": t, "plant_state": x, "estimate": estimate, "target": target}, []

    def _impact(self, t: np.ndarray, x: np.ndarray) -> dict:
        """The impact (``BallContacts``): its force along the palm's normal, and the ball's speed
        and its speed relative to the fingertip centre at the last logged sample before the palm
        first touched it (what the velocity matching lowers), and the largest fraction of the
        ball's velocity the hand could have had there at the full joint speed limits
        (``Planner.match_bound``).  None when the palm was not touched."""
        if "axis" not in self.impact:
            return {"impact_force_n": None, "impact_speed_m_s": None, "ball_speed_at_impact_m_s": None,
                    "match_bound": None}
        plant = self.station.plant
        context = plant.CreateDefaultContext()
        i = max(int(np.searchsorted(t, self.impact["time"])) - 1, 0)
        plant.SetPositionsAndVelocities(context, x[i])
        tip = plant.GetFrameByName(TIP).CalcSpatialVelocity(context, plant.world_frame(), plant.world_frame())
        ball = self.station.ball.EvalSpatialVelocityInWorld(context).translational()
        return {"impact_force_n": self.impact["peak"],
                "impact_speed_m_s": float(np.linalg.norm(ball - tip.translational())),
                "ball_speed_at_impact_m_s": float(np.linalg.norm(ball)),
                "match_bound": self.planner.match_bound(x[i, :7], ball)}

    def _joint_speeds(self, x: np.ndarray) -> dict:
        """The arm's largest joint speed over the run as a fraction of its limit, and that joint
        (1–7): the simulated plant does not enforce the limits, so this is what shows them kept."""
        nq = self.station.plant.num_positions()
        ratio = np.abs(x[:, nq:nq + 7]) / self.planner.v_max
        j = int(np.argmax(np.max(ratio, axis=0)))
        return {"joint_speed_ratio_max": float(ratio[:, j].max()), "joint_speed_ratio_joint": j + 1}

    def _logs(self) -> tuple:
        return self.logger, self.estimate_log, self.target_log


def _span(a: float, b: float) -> float:
    """b − a, rounded down so that a + (b − a) ≤ b (a segment ends before the next one starts)."""
    tf = b - a
    while a + tf > b:
        tf = np.nextafter(tf, 0.0)
    return float(tf)


def _plan_row(plan) -> dict:
    """A plan as the metrics list the revisions: when it was made, its catch time and point."""
    return {"t_plan": round(plan.t_plan, 6), "t_catch": round(plan.t_catch, 6), "match": round(plan.match, 3),
            "point": np.round(plan.point, 5).tolist(), "tf_min": round(plan.tf_min, 4),
            "speed_ratio": round(plan.speed_ratio, 3)}
