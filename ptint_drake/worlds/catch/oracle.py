"""The catch study's yardstick (issue 46): the frozen reachability oracle's verdicts
(``scripts/catch_oracle.py``, run once over throws 0–199 into ``data/oracle_0_199.json``) and
the rows and summary of ``ptint robust`` on a catch scenario.

A throw the oracle calls reachable and the planner refuses counts as a miss (``not reachable``
is then a failure like any other); a throw outside the file's seeds has no verdict (None) and
is left out of the reachable counts."""

from __future__ import annotations

import functools
import json
from collections import Counter
from pathlib import Path

DATA = Path(__file__).parent / "data" / "oracle_0_199.json"


@functools.lru_cache(maxsize=1)
def verdicts() -> dict:
    """Throw seed → the oracle's ``catchable`` (bool)."""
    rows = json.loads(DATA.read_text())["rows"]
    return {int(r["seed"]): bool(r["catchable"]) for r in rows}


def reachable(seed: int):
    """The oracle's verdict on throw ``seed`` (None outside the file's seeds)."""
    return verdicts().get(int(seed))


def row(seed: int, params: dict, metrics: dict) -> dict:
    """One robust sample of a catch scenario."""
    c = metrics.get("catch", {})
    err = c.get("error_at_catch_m")
    return {"seed": seed, "params": params, "ok": metrics["status"] == "ok", "status": metrics["status"],
            "reasons": metrics.get("reasons", []), "outcome": c.get("outcome", "error"),
            "reachable": reachable(params.get("throw", seed)),
            "error_at_catch_mm": None if err is None else 1e3 * err,
            "peak_contact_force_n": c.get("peak_contact_force_n"),
            "impact_force_n": c.get("impact_force_n"), "impact_speed_m_s": c.get("impact_speed_m_s"),
            "ball_speed_at_impact_m_s": c.get("ball_speed_at_impact_m_s"),
            "match_bound": c.get("match_bound"),
            "joint_speed_ratio_max": c.get("joint_speed_ratio_max"),
            "plans": len(c.get("plans", [])),
            "realtime_factor": metrics["sim"]["realtime_factor"], "warnings": metrics.get("warnings", [])}


def summary(rows: list) -> dict:
    """Catch rate, the oracle's reachable rate, the rate over the reachable throws, failures by
    reason (the outcome's name; an error run as ``error``), the median error, the medians over the
    caught throws of the largest force on the ball, of the impact force and of the ball's speed
    relative to the hand at the impact (``outcome.BallContacts``, ``run.CatchRun``) and of the
    matched fraction the joints' limits allow there (``Planner.match_bound``), and the
    largest joint speed of any run over its limit."""
    n = len(rows)
    caught = [r for r in rows if r.get("outcome") == "caught"]
    known = [r for r in rows if r.get("reachable") is not None]
    reach = [r for r in known if r["reachable"]]
    errors = sorted(r["error_at_catch_mm"] for r in rows if r.get("error_at_catch_mm") is not None)
    forces = sorted(r["peak_contact_force_n"] for r in caught if r.get("peak_contact_force_n") is not None)
    impacts = sorted(r["impact_force_n"] for r in caught if r.get("impact_force_n") is not None)
    speeds_in = sorted(r["impact_speed_m_s"] for r in caught if r.get("impact_speed_m_s") is not None)
    bounds = sorted(r["match_bound"] for r in caught if r.get("match_bound") is not None)
    speeds = [r["joint_speed_ratio_max"] for r in rows if r.get("joint_speed_ratio_max") is not None]
    return {"catch": {
        "throws": n, "caught": len(caught), "catch_rate": len(caught) / n if n else None,
        "reachable_rate": len(reach) / len(known) if known else None,
        "caught_of_reachable": (sum(r.get("outcome") == "caught" for r in reach) / len(reach)
                                if reach else None),
        "failures_by_reason": dict(Counter(
            r.get("outcome", "error") for r in rows if r.get("outcome") != "caught").most_common()),
        "error_at_catch_mm_median": errors[len(errors) // 2] if errors else None,
        "peak_force_caught_n_median": forces[len(forces) // 2] if forces else None,
        "impact_force_caught_n_median": impacts[len(impacts) // 2] if impacts else None,
        "impact_speed_caught_m_s_median": speeds_in[len(speeds_in) // 2] if speeds_in else None,
        "match_bound_caught_median": bounds[len(bounds) // 2] if bounds else None,
        "joint_speed_ratio_max": max(speeds) if speeds else None}}
