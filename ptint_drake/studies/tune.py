"""Gains for any arm (``ptint tune``): the smallest K (or Λ; the largest φ) that meets the
prescribed time on every plant variant, with a margin.

A gain value *works* when, on every variant (``scenario.apply_variant``), every
segment meets the scenario's verdict with the bounds divided by the margin M
(e(tf) ≤ e_tf / M, hold ≤ hold / M; "not early" as is) and the actuators saturate
at most a fraction F of the time.  The search is 1-D:

1. a bracket from the model (an offline design step may use it; the tuned
   controller stays model-free): for K, from M_max / tf (below it the arm's slowest
   velocity time constant M/K exceeds tf) to the gain at which a 1 cm/s surface error
   asks the weakest actuator for its whole effort limit (τ = K J⁺ s_x); for Λ, φ and
   ``rot_scale`` (m per rad, only for ``controller.task`` pose or top_down), a factor 30
   either side of the scenario's value;
2. a coarse log-spaced grid over the bracket, every value × variant in parallel;
3. bisection (in log) inside the first working bracket of the grid — for K and Λ the
   first failing → working step from below, for φ the last working → failing step —
   until the bracket's ratio is within ``tolerance``.  Pass/fail need not be monotone
   in the gain; the grid shows it (``tune.png``).

Nothing is written when no value works; the reasons of the best value are reported.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ptint_drake.simulation import simulate
from ptint_drake.simulation.scenario import (LoadedScenario, ScenarioError, apply_variant, check_variants,
                                             parse_scenario)
from ptint_drake.studies.runner import run_tasks
from ptint_drake.verdict.metrics import segment_reasons
from ptint_drake.worlds.registry import world_of

GAINS = ("K", "Lambda", "phi", "rot_scale")
POSE_GAINS = ("rot_scale",)  # only for a controller.task other than position
# rad: a redundant arm whose null-space offset from the start posture ends above this drifts
DRIFT_ANGLE = 0.5
DEFAULT_VARIANTS = ("nominal", "mass_x0.7", "mass_x1.5")


@dataclass
class TuneSettings:
    gain: str = "K"
    variants: tuple = DEFAULT_VARIANTS
    margin: float = 2.0  # the criteria's bounds are divided by this
    max_saturation: float = 0.05  # largest fraction of the time any actuator may saturate
    grid_points: int = 8
    tolerance: float = 0.05  # stop bisecting when hi / lo ≤ 1 + tolerance
    max_bisections: int = 8
    bracket: tuple = field(default_factory=tuple)  # (lo, hi) to override the model's


PARAM_PREFIX = "params."  # ``--gain params.NAME``: a plugin controller's parameter


def check_gain(gain: str, bracket) -> None:
    """A paper gain (``GAINS``), or ``params.NAME`` of a plugin with its ``--range``."""
    if gain.startswith(PARAM_PREFIX):
        if not gain[len(PARAM_PREFIX):].isidentifier():
            raise ScenarioError(f"--gain: {gain!r} is not params.NAME")
        if not bracket:
            raise ScenarioError(f"--range: {gain} needs --range LO,HI (no model-derived bracket exists "
                                f"for a plugin's parameter)")
    elif gain not in GAINS:
        raise ScenarioError(f"--gain: must be one of {', '.join(GAINS)} or params.NAME, got {gain!r}")


def check_task_gain(scenario, gain: str) -> None:
    """``rot_scale`` weighs the orientation rows: a ``position`` task has none to tune."""
    if gain in POSE_GAINS and scenario.controller.task == "position":
        raise ScenarioError(f"--gain: {gain} weighs the orientation error, but controller.task of this "
                            f"scenario is position (tune it on a pose or top_down scenario)")


def gain_value(scenario, gain: str):
    """The scenario's current value of ``gain`` (None for a plugin parameter it does not set)."""
    if gain.startswith(PARAM_PREFIX):
        return scenario.controller.params.get(gain[len(PARAM_PREFIX):])
    return getattr(scenario.controller, gain)


def _set_gain(scenario, gain: str, value: float):
    out = copy.deepcopy(scenario)
    if gain.startswith(PARAM_PREFIX):
        out.controller.params = dict(out.controller.params) | {gain[len(PARAM_PREFIX):]: float(value)}
    else:
        setattr(out.controller, gain, float(value))
    return out


def _all_gains(scenario, gain: str, value: float) -> dict:
    """tune.json's ``gains``: the tunable values of the scenario's controller, the chosen one set."""
    if gain.startswith(PARAM_PREFIX):
        own = {PARAM_PREFIX + k: v for k, v in scenario.controller.params.items()}
    else:
        own = {g: getattr(scenario.controller, g) for g in GAINS
               if g not in POSE_GAINS or scenario.controller.task != "position"}
    return own | {gain: value}


def tune_run(text: str, name: str, gain: str, value: float, variant: str, margin: float,
             max_saturation: float) -> dict:
    """One (gain value, variant) run, in a worker: the row of ``tune.json``'s ``tried``."""
    scenario = apply_variant(_set_gain(parse_scenario(text, name), gain, value), variant)
    row = {"gains": {gain: float(value)}, "variant": variant}
    try:
        m = simulate(scenario, check=False).metrics
    except (ScenarioError, RuntimeError, ValueError) as exc:
        return row | {"ok": False, "reasons": [" ".join(str(exc).split())[:200]], "e_tf_norm": None,
                      "e_hold_max_norm": None, "saturated_fraction": None}
    reasons = [m["failure"]["message"]] if m.get("failure") else sorted(
        {r for seg in m["segments"] for r in segment_reasons(seg, scenario.criteria, margin)})
    if m["saturated_fraction"] > max_saturation:
        reasons.append("saturation")
    e_tf = [s["e_tf_norm"] for s in m["segments"]]
    hold = [s["e_hold_max_norm"] for s in m["segments"]]
    return row | {
        "ok": not reasons, "reasons": reasons,
        "e_tf_norm": None if None in e_tf else max(e_tf),
        "e_hold_max_norm": None if None in hold else max(hold),
        "saturated_fraction": m["saturated_fraction"],
        "self_motion_final": m["self_motion_final"],
    }


def model_bracket(scenario, gain: str) -> tuple[float, float]:
    """The search range of ``gain`` from the model at the start pose (see the module docstring)."""
    check_gain(gain, None)
    current = gain_value(scenario, gain)
    if gain != "K":
        return current / 30.0, current * 30.0
    from pydrake.multibody.tree import JacobianWrtVariable  # noqa: PLC0415

    from ptint_drake.robot.plant import actuator_effort_limits, make_plant  # noqa: PLC0415

    plant = make_plant(scenario)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, np.radians(scenario.robot.initial_q_deg))
    M = plant.CalcMassMatrix(context)
    frame = plant.GetFrameByName(scenario.robot.end_effector)
    J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3),
                                                plant.world_frame(), plant.world_frame())
    tf = min(ic.tf for ic in scenario.interceptions)
    lo = float(np.linalg.eigvalsh(M).max()) / tf
    limits = actuator_effort_limits(plant)
    finite = limits[np.isfinite(limits)]
    weakest = float(finite.min()) if len(finite) else 100.0
    hi = weakest / (np.linalg.norm(np.linalg.pinv(J), 2) * 0.01)
    return lo, max(hi, 10.0 * lo)


def _evaluate(text, name, settings: TuneSettings, values, workers, dask, progress, tried, folders=()) -> dict:
    """ok of every value (all variants), running values × variants in parallel (``folders``: where
    a plugin controller's module is looked for)."""
    tasks = [(text, name, settings.gain, v, variant, settings.margin, settings.max_saturation)
             for v in values for variant in settings.variants]
    rows = run_tasks(tune_run, tasks, workers=workers, dask=dask, progress=progress, folders=folders)
    tried.extend(rows)
    n = len(settings.variants)
    return {v: all(r["ok"] for r in rows[i * n:(i + 1) * n]) for i, v in enumerate(values)}


def _first_bracket(grid, ok: dict, smallest: bool):
    """(fails, works) neighbours of the grid: the first working value from below (smallest)
    or the last working value before a failure from above (largest)."""
    if smallest:
        for i, v in enumerate(grid):
            if ok[v]:
                return (grid[i - 1] if i else None), v
    else:
        for i in range(len(grid) - 1, -1, -1):
            if ok[grid[i]]:
                return (grid[i + 1] if i + 1 < len(grid) else None), grid[i]
    return None, None


def run_tune(loaded: LoadedScenario, settings: TuneSettings, workers=None, dask=None,
             progress=None, say=print) -> dict:
    """The search on the scenario ``loaded`` (each run rebuilt from its text); returns the
    content of tune.json (plus ``scenario`` for tuned.yaml)."""
    t0 = time.perf_counter()
    text, name, scenario = loaded.text, loaded.name, loaded.scenario
    refusal = world_of(scenario).tune_refusal(name)  # a verdict tune cannot read (the picks')
    if refusal:
        raise ScenarioError(refusal)
    check_variants(scenario, settings.variants)
    check_gain(settings.gain, settings.bracket)
    check_task_gain(scenario, settings.gain)
    lo, hi = settings.bracket or model_bracket(scenario, settings.gain)
    grid = list(np.geomspace(lo, hi, settings.grid_points))
    smallest = settings.gain != "phi"
    tried: list = []
    say(f"tune: {settings.gain} in [{lo:.4g}, {hi:.4g}] (grid of {len(grid)}), variants "
        f"{', '.join(settings.variants)}, margin {settings.margin:g}")
    ok = _evaluate(text, name, settings, grid, workers, dask, progress, tried, loaded.folders)
    fails, works = _first_bracket(grid, ok, smallest)
    steps = 0
    while works is not None and fails is not None and steps < settings.max_bisections \
            and max(works, fails) / min(works, fails) > 1.0 + settings.tolerance:
        mid = math.sqrt(works * fails)
        say(f"tune: bisect {settings.gain} between {min(works, fails):.4g} and {max(works, fails):.4g}")
        if _evaluate(text, name, settings, [mid], workers, dask, progress, tried, loaded.folders)[mid]:
            works = mid
        else:
            fails = mid
        steps += 1
    result = {"scenario": name, "gain": settings.gain, "margin": settings.margin,
              "max_saturation": settings.max_saturation, "variants": list(settings.variants),
              "bracket": [lo, hi], "grid": grid, "tolerance": settings.tolerance,
              "paper_value": gain_value(scenario, settings.gain),
              "criteria": dataclasses.asdict(scenario.criteria),
              "tried": tried, "wall_time_s": time.perf_counter() - t0, "runs": len(tried)}
    if works is None:
        result |= {"gains": None, "smallest_working": None,
                   "reasons": sorted({r for row in tried for r in row["reasons"]})}
        return result
    value = float(works)
    best = {row["variant"]: row for row in tried if row["gains"][settings.gain] == works}
    gains = _all_gains(scenario, settings.gain, value)
    drift = [row["self_motion_final"] for row in best.values() if row.get("self_motion_final") is not None]
    if drift:  # redundant arm: does J⁺ leave it drifting in its null space?
        result["self_motion_final"] = max(drift)
        result["drifts"] = max(drift) > DRIFT_ANGLE
        result["null_space_damping"] = float(scenario.controller.null_space_damping)
    # tune.json's contract names the chosen value smallest_working; for φ it is the largest
    result |= {"gains": gains, "smallest_working": {settings.gain: value, "per_variant": best},
               "scenario_obj": _portable(_set_gain(scenario, settings.gain, value))}
    if not smallest:
        result["largest_working"] = result["smallest_working"]
    return result


def _portable(scenario):
    """The scenario with its model file written as an absolute path (bundled names stay),
    so that tuned.yaml runs from any folder."""
    from ptint_drake.robot.plant import resolve_model  # noqa: PLC0415
    from ptint_drake.robot.rvm1 import bundled_models  # noqa: PLC0415

    if scenario.robot.model not in bundled_models():
        scenario.robot.model = str(resolve_model(scenario.robot.model).resolve())
    return scenario


def _mm(value) -> str:
    return "n/a" if value is None else f"{value * 1e3:.3g} mm"


def summary_line(result: dict) -> str:
    """``K = 148 (margin 2: nominal 0.09 mm, mass_x1.5 0.08 mm; paper 50)``, or why none works."""
    gain = result["gain"]
    if result["gains"] is None:
        return (f"no {gain} in [{result['bracket'][0]:.4g}, {result['bracket'][1]:.4g}] meets the "
                f"criteria with margin {result['margin']:g} on every variant "
                f"({', '.join(result['reasons']) or 'no run completed'})")
    per = result["smallest_working"]["per_variant"]
    value = result["gains"][gain]
    parts = ", ".join(f"{v} {_mm(per[v]['e_tf_norm'])}" for v in result["variants"] if v in per)
    paper = result["paper_value"]
    relation = "the scenario's" if math.isclose(value, paper, rel_tol=0.01) else (
        f"{value / paper:.2f} × the scenario's {paper:g}")
    line = (f"{gain} = {value:.4g} (margin {result['margin']:g}: e(tf) {parts}; {relation}) "
            f"after {result['runs']} runs in {result['wall_time_s']:.0f} s")
    if "drifts" in result:
        damping = result.get("null_space_damping", 0.0)
        advice = (f" — it drifts with controller.null_space_damping {damping:g}: a larger value holds "
                  "it closer" if damping > 0.0
                  else " — it drifts: consider controller.null_space_damping (e.g. 10)")
        line += (f"; redundant arm: {result['self_motion_final']:.2g} rad from its start posture in the "
                 f"null space at the end" + (advice if result["drifts"] else ""))
    return line


def figure(result: dict, out_dir: Path) -> None:
    """e(tf) and hold max against the gain, one line per variant, criteria and choice marked."""
    from ptint_drake.views.plots import plt, save  # noqa: PLC0415

    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained", sharex=True)
    gain = result["gain"]
    crit = result.get("criteria", {"e_tf": 1e-3, "hold": 3e-3})
    for variant in result["variants"]:
        rows = sorted((r for r in result["tried"] if r["variant"] == variant and r["e_tf_norm"] is not None),
                      key=lambda r: r["gains"][gain])
        x = [r["gains"][gain] for r in rows]
        for ax, key in zip(axes, ("e_tf_norm", "e_hold_max_norm")):
            ax.loglog(x, [max(r[key], 1e-7) * 1e3 for r in rows], "o-", ms=3, label=variant)
    for ax, key, label in ((axes[0], "e_tf", "|e(tf)| [mm]"), (axes[1], "hold", "hold max |e| [mm]")):
        ax.axhline(crit[key] * 1e3, color="r", lw=0.8, label="criterion")
        ax.axhline(crit[key] * 1e3 / result["margin"], color="r", ls="--", lw=0.8,
                   label=f"criterion / {result['margin']:g}")
        if result["gains"] is not None:
            ax.axvline(result["gains"][gain], color="k", lw=0.8, label="chosen")
        ax.set_xlabel(gain)
        ax.set_ylabel(label)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"{result['scenario']}: tuning {gain}")
    save(fig, out_dir, "tune")


def write_tune(result: dict, out_dir: Path) -> None:
    """tune.json, tune.png and (only when a value works) tuned.yaml, staged then moved in."""
    from ptint_drake.outputs.folder import staged_output, write_json_atomic  # noqa: PLC0415
    from ptint_drake.simulation.scenario import dump_yaml  # noqa: PLC0415

    with staged_output(out_dir) as stage:
        scenario = result.get("scenario_obj")
        if scenario is not None:
            (stage / "tuned.yaml").write_text(
                f"# {summary_line(result)}\n# written by ptint tune; run it with: ptint run tuned.yaml\n"
                + dump_yaml(scenario))
        figure(result, stage)
        write_json_atomic(stage / "tune.json", {k: v for k, v in result.items() if k != "scenario_obj"})
