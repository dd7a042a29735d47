"""A line's Monte Carlo sample (``ptint robust`` on a ``pick.line`` scenario, issue 44): what is
drawn for it, on the truth side only, and what its row keeps — the parts, not the tasks.

A line has no parts and no tasks before its run (``arrivals``), so the pick study's draws
(``worlds.pick.studies.robust_sample``: per declared part, per task) are made per *pool part* —
the parts the arrivals bring, in release order, known before the run from ``line.seed`` — and
written into the scenario's truth-only fields, which the controller side never reads:

1. the arm's link masses (``mass``, as the pick study);
2. per pool part, its mass and friction (``part_mass``, ``part_friction``:
   ``pick.line.truth.mass`` / ``friction``; the catalog, the controller side's object model,
   keeps the kind's);
3. per line belt, its speed (``belt_speed``, ×): a ``pick.line.speed_steps`` step at t = 0 (the
   drive at that factor from the start) and every later step of that belt scaled by it; the
   declared ``pick.belts[*].speed`` is unchanged, so a belt without an encoder is predicted at its
   declared speed until its tracks show otherwise (``line.driver``);
4. per pool part, its close-command jitter (``close_jitter``: ``pick.line.truth.close_delay``);
5. per pool part, its lateral shift (``part_lateral``: ``pick.line.truth.lateral``).

The order is the pick study's (masses, parts, belts, closes, laterals).  A sample's every part is
judged: ``placed`` (the line's metric: within ``criteria`` at the end) with no collision in its
task, else its reason — the line's own (``line.metrics``: the task's verdict code, or the
scheduler's last word) or ``not entered by the end`` (the part never reached its reach window:
the run ended first).  ``holdable`` is ``hold_limit``'s bound from the drawn truth, with the lift
the line's tasks make (``PickTaskConfig``'s default).
"""

from __future__ import annotations

from ptint_drake.config.line import SpeedStepConfig
from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.worlds.pick.hold_limit import hold_margin
from ptint_drake.worlds.pick.line.arrivals import line_pool

NOT_ENTERED = "not entered by the end"


def _belt_speeds(scenario, u) -> list:
    """Step 3 (module docstring): every line belt's drawn truth speed (m/s)."""
    line, declared = scenario.pick.line, {b.name: b.speed for b in scenario.pick.belts}
    speeds, starts = [], []
    for belt in line.belts:
        factor = float(u("belt_speed"))
        for step in line.speed_steps:
            if step.belt == belt.name:
                step.factor *= factor
        starts.append(SpeedStepConfig(belt=belt.name, t=0.0, factor=factor))
        speeds.append(factor * declared[belt.name])
    line.speed_steps = starts + line.speed_steps
    return speeds


def line_sample(scenario, name: str, seed: int, u) -> tuple:
    """The line scenario of one sample and its parameters (module docstring), drawn by ``u``
    (``studies.robust.Draws``)."""
    scenario.plant.mass_scale = float(u("mass"))
    pick, line = scenario.pick, scenario.pick.line
    pool, _ = line_pool(line, scenario.duration)
    truth = line.truth
    truth.mass, truth.friction = [], []
    for _ in pool:
        truth.mass.append(float(u("part_mass")))
        truth.friction.append(float(u("part_friction")))
    speeds = _belt_speeds(scenario, u)
    truth.close_delay = [float(u("close_jitter")) for _ in pool]
    truth.lateral = [float(u("part_lateral")) for _ in pool]
    scenario.name = f"{name}_seed{seed}"
    task = PickTaskConfig()
    holdable = [hold_margin(m, mu, pick.gripper, task.lift_height, task.lift) >= 1.0
                for m, mu in zip(truth.mass, truth.friction)]
    params = {"mass_scale": scenario.plant.mass_scale, "parts": [p.name for p in pool],
              "part_mass": list(truth.mass), "part_friction": list(truth.friction),
              "belt_speed": speeds, "belt_encoder": [b.encoder for b in line.belts],
              "close_delay": list(truth.close_delay), "part_lateral": list(truth.lateral),
              "holdable": holdable}
    return scenario, params


def line_row(seed: int, params: dict, m: dict) -> dict:
    """What a line sample keeps: per pool part (release order) whether it entered and was placed,
    its task's collision and place error, and its reason (module docstring); the verdict's
    reasons are those, without the part's name (the study counts reasons, not parts)."""
    picks, reasons = [], []
    for p in m["line"]["parts"]:
        pick = m["picks"][p["task"]] if p["task"] is not None else {}
        reason = p["reason"] if p["entered"] else NOT_ENTERED
        row = {"part": p["part"], "entered": p["entered"], "placed": p["placed"], "task": p["task"],
               "collision": bool(pick.get("collision")), "place_error_mm": pick.get("place_error_mm"),
               "place_error_deg": pick.get("place_error_deg"), "t_grasp": pick.get("t_grasp"),
               "t_grasp_prescribed": pick.get("t_grasp_prescribed"),
               "t_close_command": pick.get("t_close_command"),
               "reason": None if p["placed"] else reason}
        if pick.get("collision") and p["placed"]:  # placed, but its task touched something
            reasons.append("collision with " + ", ".join(pick.get("collision_with") or ["?"]))
        elif not p["placed"]:
            reasons.append(reason)
        picks.append(row)
    e_tf = [s["e_tf_norm"] for s in m["segments"]]
    line = m["line"]
    return {"seed": seed, "params": params, "ok": m["status"] == "ok", "status": m["status"],
            "e_tf": e_tf, "e_tf_max": max((v for v in e_tf if v is not None), default=None),
            "picks": picks, "reasons": reasons, "realtime_factor": m["sim"]["realtime_factor"],
            "warnings": m["warnings"], "line": {"entered": line["entered"], "placed": line["placed"],
                                                 "replaced": len(line["replaced"]),
                                                 "decisions": len(line["decisions"])}}
