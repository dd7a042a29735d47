"""The catch world (issue 46) on the world seam: a scenario with a ``catch`` block.

``ptint robust <catch scenario> --samples N``: sample i is throw ``seed + i`` of the frozen thrower,
seen by the camera with noise seed ``seed + i`` (the arm's own deviations are not drawn: the
catch station takes none); each row keeps the named outcome, the hand's error against the true
ball at t_catch, the peak contact force on the ball and the oracle's verdict on that throw
(``oracle``); robust.json's summary adds the catch rate, the oracle's reachable rate, the catch
rate over the reachable throws and the failures by reason (``oracle.summary``)."""

from __future__ import annotations

from pathlib import Path

from pydrake.common.yaml import yaml_load_typed

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.fields import nonnegative
from ptint_drake.config.schema import Scenario
from ptint_drake.config.yaml_io import dump_yaml
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.verdict.metrics import Reason
from ptint_drake.worlds.base import World
from ptint_drake.worlds.catch import oracle
from ptint_drake.worlds.catch.run import CatchRun


class CatchWorld(World):
    """A thrown ball caught in the hand at a time the planner chooses (``worlds.catch``)."""

    name = "catch"
    block = "catch"
    summary = "a thrown foam ball caught in the hand of the iiwa 14 with a WSG 50-110"

    def schedule(self, scenario) -> Schedule:
        c = scenario.catch
        return Schedule([Segment(0.0, c.sensing, c.beta), Segment(c.sensing, 0.6, c.beta)])

    def validate(self, scenario) -> None:
        """The simulated arm may be scaled (``plant.mass_scale``: ``ptint compare``'s ``mass_xF``
        variants, applied in ``CatchRun.initialize``); the other plant deviations are not
        modelled in the catch station: one line naming the field.  ``catch.close_lag`` ≥ 0 (the
        jaws reach the ball after the catch time, not before)."""
        nonnegative(scenario.catch.close_lag, "catch.close_lag")
        p = scenario.plant
        if p.payload_kg != 0.0:
            raise ScenarioError("plant.payload_kg: not used in a catch scenario (the hand is the payload)")
        if p.damping_scale != 1.0 or p.coulomb or p.disturbance.amplitude or p.disturbance.step:
            raise ScenarioError("plant: a catch scenario takes mass_scale only")

    def prepare(self, scenario, log: bool = True) -> CatchRun:
        return CatchRun(scenario, log)

    def reasons(self, metrics: dict, criteria) -> list:
        name = metrics.get("catch", {}).get("outcome")
        return [] if name == "caught" else [Reason(None, "catch", f"not caught: {name}")]

    def view_tasks(self, scenario, series: dict, metrics: dict, stage: Path, figures: bool,
                   replay: bool, svg: bool) -> list[tuple]:
        """The replay (``views``), when asked for."""
        if not replay:
            return []
        return [("catch_replay", series, metrics, stage, scenario.name, (dump_yaml(scenario),))]

    def draw_view(self, name: str, series: dict, metrics: dict, stage: Path, title: str, args: tuple) -> str:
        from ptint_drake.worlds.catch.views import write_catch_replay  # noqa: PLC0415

        scenario = yaml_load_typed(schema=Scenario, data=args[0])
        write_catch_replay(scenario, series, metrics, stage / "replay.html", title=title)
        return name

    def compare_scenario(self, scenario, controller: str):
        """``ptint compare``: a controller that has only the position task (``ct_quintic``) aims
        the hand's fingertip centre at the same planner's moving catch target, the hand's
        orientation left to it (the catch posture's is ptsmc's pose task)."""
        if controller != "ptsmc" and scenario.controller.task != "position":
            scenario.controller.task = "position"
        return scenario

    def compare_row(self, metrics: dict, series: dict) -> dict:
        """The catch's row: its outcome, the hand's error, the peak force and the largest joint
        speed over its limit (``world``: what ``studies.compare`` tables beside the controller)."""
        c = metrics["catch"]
        err, impact = c["error_at_catch_m"], c.get("impact_force_n")
        return {"ok": metrics["status"] == "ok", "status": metrics["status"], "reasons": metrics["reasons"],
                "reason_codes": metrics["reason_codes"], "torque_peak_max": None, "segments": [],
                "realtime_factor": metrics["sim"]["realtime_factor"],
                "world": {"throw": c["throw"], "outcome": c["outcome"], "plans": len(c["plans"]),
                          "hand error (mm)": None if err is None else round(1e3 * err, 1),
                          "peak force (N)": round(c["peak_contact_force_n"], 1),
                          "impact (N)": None if impact is None else round(impact, 1),
                          "joint speed / limit": round(c["joint_speed_ratio_max"], 2)}}

    def own_plant_step(self, scenario) -> float:
        return scenario.catch.time_step

    def robust_sample(self, scenario, name: str, seed: int, u) -> tuple:
        scenario.catch.throw = int(seed)
        scenario.measurement.seed = int(seed)
        return scenario, {"throw": int(seed)}

    def robust_row(self, seed: int, params: dict, metrics: dict) -> dict:
        return oracle.row(seed, params, metrics)

    def robust_summary(self, rows: list) -> dict:
        return oracle.summary(rows)
