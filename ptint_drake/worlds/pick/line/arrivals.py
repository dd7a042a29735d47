"""The arrival process of a line (``config.line.ArrivalConfig``) and the pool of parts it makes.

Drake adds no body to a finalized plant, so the arrivals are drawn before the station is built:
per arrival block ``k`` a generator seeded by (``line.seed``, k) draws the release times over
[``start``, duration − ``until``) and, per release, the kind (by the ``mix`` weights), the lateral
offset and the yaw (uniform in their [min, max]).  Each release becomes an ordinary
``PartConfig`` (named ``<kind>_<n>``, n in release order over the whole line), so the station,
the tracker, the metrics and the views take the pool as any list of parts; its ``offset`` is the
release point on its belt.  The truth side parks every part until its release (``truth``).
``line.truth`` (``config.line.PoolTruthConfig``) then gives pool part n its drawn mass, friction
and lateral shift (the robust study's; the catalog, which the controller side reads, keeps the
kind's).

The process (a choice the issue leaves open): ``poisson`` is a Poisson process with a dead time
— gaps ``min_gap`` + Exp(1/rate − ``min_gap``), so the mean gap stays 1/rate while no two parts
are put on the belt closer than ``min_gap`` × speed (a real feeder's singulation); ``jittered``
is a period of 1/rate, each gap × (1 ± ``jitter``) uniformly, at least ``min_gap``.  Rates are per
second, not spacings: a faster belt spreads the same parts farther apart.  On the truth side
(``line_scenario``) a release is then delayed, where needed, until the belt has carried the part
before it clear (``spaced``): ``min_gap`` is a time, and a slow belt covers little in it.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.line import ArrivalConfig, LineConfig, PoolTruthConfig
from ptint_drake.config.part_shape import footprint_radius
from ptint_drake.config.pick import PartConfig

SPACING = 0.005  # m: the least free belt between two parts as the feeder releases them (``spaced``)


@dataclass(frozen=True)
class Release:
    """Pool part ``part`` (index in the expanded ``pick.parts``) is put on ``belt`` at ``t`` (s)."""

    part: int
    t: float
    belt: str
    kind: str


def release_times(arrival: ArrivalConfig, end: float, rng: np.random.Generator) -> list[float]:
    """The release times of one arrival block in [start, end) (module docstring)."""
    mean = 1.0 / arrival.rate
    if arrival.process == "poisson" and mean <= arrival.min_gap:
        raise ScenarioError(f"pick.line.arrivals: rate {arrival.rate}/s leaves no time beyond min_gap "
                            f"{arrival.min_gap} s between parts")
    times, t = [], arrival.start
    if arrival.process == "poisson":
        t += rng.exponential(mean - arrival.min_gap)
    while t < end:
        times.append(float(t))
        if arrival.process == "poisson":
            gap = arrival.min_gap + rng.exponential(mean - arrival.min_gap)
        else:
            gap = max(arrival.min_gap, mean * (1.0 + rng.uniform(-arrival.jitter, arrival.jitter)))
        t += gap
    return times


def _kinds(line: LineConfig, arrival: ArrivalConfig) -> tuple[list, np.ndarray]:
    names = [c.name for c in line.catalog]
    weights = np.array([arrival.mix.get(n, 0.0) if arrival.mix else 1.0 for n in names], dtype=float)
    if not weights.sum() > 0.0:
        raise ScenarioError("pick.line.arrivals: mix: the weights sum to 0")
    return names, weights / weights.sum()


def belt_speed_at(belt: str, speed: float, steps: list, t: float) -> float:
    """m/s: belt ``belt``'s speed at ``t`` on the truth side — ``speed`` (its declared) × the
    factor of the last of ``steps`` (``line.speed_steps``) on it at or before ``t``."""
    factor = 1.0
    for step in sorted((s for s in steps if s.belt == belt), key=lambda s: s.t):
        if step.t <= t:
            factor = step.factor
    return factor * speed


def spaced(times: list[float], radii: list[float], belt: str, speed: float, steps: list) -> list[float]:
    """The release times ``times`` (one belt's, in order) each delayed as little as needed so that
    the belt has carried the part before it at least the two footprint radii (``radii``) and
    ``SPACING`` farther (a feeder puts no part onto the one before it: ``min_gap`` is a time, and
    on a slow belt it alone let two 40 mm parts be released 31 mm apart); the belt's travel
    integrated over its speed steps.  A belt stopped at the end keeps a release waiting forever
    (``inf``: never released)."""
    out: list[float] = []
    cuts = sorted({s.t for s in steps if s.belt == belt})
    for k, t in enumerate(times):
        if out:
            need = radii[k - 1] + radii[k] + SPACING
            t = max(t, _after_travel(out[-1], need, belt, speed, steps, cuts))
        out.append(float(t))
    return out


def _after_travel(t0: float, distance: float, belt: str, speed: float, steps: list, cuts: list) -> float:
    """s: when the belt has carried a point ``distance`` m from where it was at ``t0``."""
    t, left = t0, distance
    for cut in [c for c in cuts if c > t0] + [np.inf]:
        v = belt_speed_at(belt, speed, steps, t)
        if v > 0.0 and t + left / v <= cut:
            return t + left / v
        left -= v * (cut - t)
        t = cut
    return np.inf


def line_pool(line: LineConfig, duration: float, speeds: dict[str, float] | None = None
              ) -> tuple[list[PartConfig], list[Release]]:
    """The pool of parts (release order) and their releases of ``line`` over ``duration``; with
    ``speeds`` (belt name → its declared m/s) each belt's releases ``spaced`` along it.  A draw
    delayed past its block's window (``until`` before the end) is not released: its part stays in
    the pool, parked the whole run (as ``idle_part``), so the pool's size does not depend on the
    speeds (the robust study draws per pool part before it draws the belts' speeds)."""
    drawn = []
    catalog = {c.name: c for c in line.catalog}
    for k, arrival in enumerate(line.arrivals):
        rng = np.random.default_rng([line.seed, k])
        names, weights = _kinds(line, arrival)
        for t in release_times(arrival, duration - arrival.until, rng):
            kind = names[int(rng.choice(len(names), p=weights))]
            lateral = float(rng.uniform(*arrival.lateral))
            yaw = float(rng.uniform(*arrival.yaw_deg))
            drawn.append((t, k, kind, lateral, yaw))
    if speeds:
        drawn = _spaced_draws(drawn, line, speeds)
    drawn.sort()
    parts, releases = [], []
    for n, (t, k, kind, lateral, yaw) in enumerate(drawn):
        c, arrival = catalog[kind], line.arrivals[k]
        parts.append(PartConfig(name=f"{kind}_{n}", belt=arrival.belt, shape=c.shape, size=list(c.size),
                                offset=arrival.release, lateral=lateral, yaw_deg=yaw, mass=c.mass,
                                friction=c.friction))
        if t < duration - arrival.until:
            releases.append(Release(n, t, arrival.belt, kind))
    return parts, releases


def _spaced_draws(drawn: list, line: LineConfig, speeds: dict[str, float]) -> list:
    """``drawn`` (time, block, kind, lateral, yaw) with each belt's times ``spaced``."""
    radius = {c.name: footprint_radius(c.shape, c.size) for c in line.catalog}
    out = []
    for belt in sorted({line.arrivals[k].belt for _, k, _, _, _ in drawn}):
        mine = sorted(d for d in drawn if line.arrivals[d[1]].belt == belt)
        times = spaced([d[0] for d in mine], [radius[d[2]] for d in mine], belt, speeds[belt],
                       line.speed_steps)
        out += [(t, *d[1:]) for t, d in zip(times, mine)]
    return out


def idle_part(line: LineConfig) -> PartConfig:
    """The pool of a draw that released no part (a Poisson process at a low rate, one seed in
    many): one part of the first block's first kind, never released — parked the whole run
    (``truth``), so the station is built as for any line and the run reports nothing entered."""
    arrival = line.arrivals[0]
    names, weights = _kinds(line, arrival)
    c = line.kind(names[int(np.argmax(weights))])
    return PartConfig(name=f"{c.name}_0", belt=arrival.belt, shape=c.shape, size=list(c.size),
                      offset=arrival.release, mass=c.mass, friction=c.friction)


def pool_truth(parts: list[PartConfig], truth: PoolTruthConfig, belts: list) -> None:
    """Pool part n's mass, friction and lateral shift from ``truth`` (``PoolTruthConfig``; the
    shifted offset clipped to its belt's half width), in place; a list of another length than the
    pool is named."""
    half = {b.name: b.width / 2 for b in belts}
    for name in ("mass", "friction", "lateral", "close_delay"):
        values = getattr(truth, name)
        if values and len(values) != len(parts):
            raise ScenarioError(f"pick.line.truth.{name}: {len(values)} values for the pool's {len(parts)} "
                                f"parts (one per part, release order, or none)")
    for n, part in enumerate(parts):
        part.mass = float(truth.mass[n]) if truth.mass else part.mass
        part.friction = float(truth.friction[n]) if truth.friction else part.friction
        if truth.lateral:
            h = half[part.belt]
            part.lateral = float(np.clip(part.lateral + truth.lateral[n], -h, h))


def close_delay(truth: PoolTruthConfig, n: int) -> float:
    """s added to the close command of a task picking pool part ``n`` (``truth.close_delay``; 0
    without it): the actuation's jitter, the truth side's, which the plan does not foresee."""
    return float(truth.close_delay[n]) if truth.close_delay else 0.0


def line_scenario(scenario):
    """A copy of the line ``scenario`` whose ``pick.parts`` is the pool (``line_pool``, with its
    truth: ``pool_truth``) and whose ``pick.tasks`` is empty (the run appends what it decides);
    and the releases."""
    out = copy.deepcopy(scenario)
    line = scenario.pick.line
    parts, releases = line_pool(line, scenario.duration, {b.name: b.speed for b in scenario.pick.belts})
    if not parts:
        if all(a.start >= scenario.duration - a.until for a in line.arrivals):
            raise ScenarioError("pick.line.arrivals: no part arrives before the scenario's end (rate, "
                                "start, until, duration)")
        parts = [idle_part(line)]  # a draw that released nothing: the run goes on with its pool parked
    pool_truth(parts, scenario.pick.line.truth, scenario.pick.belts)
    out.pick.parts, out.pick.tasks = parts, []
    return out, releases
