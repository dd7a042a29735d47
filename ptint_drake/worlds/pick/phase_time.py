"""The shortest tf of a pick's phase for the arm, and the capacity of a pick cycle.

``PhaseTimes.min_tf`` — the shortest tf for which one phase's TBG profile, from a tool point to a
target (fixed, or riding a belt at a velocity) with or without a held payload, keeps every joint's
speed (|J⁺ẋ|, inverted as the controller inverts it) and torque (the inverse dynamics of the
station's plant plus the payload) within the arm model's limits along the whole profile: the
feasibility model of the warnings before a run (``feasibility.way_profile`` and
``run_warnings.joint_terms``: one evaluation, shared), times ``MARGIN``.

How it is found, without a search over tf: on a fixed way of postures q_k (the samples of
``run_warnings.profile_times`` are fixed fractions of tf, and ξ at a fraction does not depend on
tf), with u = 1/tf the tool's velocity is ẋ_target + u ξ̇₁ e0 and its acceleration u² ξ̈₁ e0 (ξ₁:
the profile of tf = 1), so the joint speeds are q̇ = A + B u and, the inverse dynamics being
quadratic in q̇ and linear in q̈, the torques τ = c₀ + c₁ u + c₂ u² — exactly.  ``joint_terms`` at
u = 0, 1 and 2 gives A, B and c₀, c₁, c₂, and the smallest positive root of |A + B u| = v_max and
|c₀ + c₁ u + c₂ u²| = τ_max over every sample and joint is the largest u, 1/tf, that fits.  A
fixed target's way does not depend on tf: one pass.  A target riding a belt moves on during the
phase, so its way does: the root is found again on the way of the last tf until it moves by less
than ``TOLERANCE`` (a fixed point; ``ITERATIONS`` at most, then the longer of the last two).  The
postures come from Drake's ``InverseKinematics`` along the way, cached by the way (an online
scheduler asks again for the same ways); ``scripts/bench_phase_time.py`` measures a call.  A call
asked again to the bit (the same points, payload, shape, yaws, start posture and margin, and for a
riding target the same first guess ``last``) returns its first answer and leaves ``last`` as that
call did (``answers``): its postures are the cached ones, so the answer is the one it would compute
again — dropped with the whole memo when a way's postures leave the cache.  Measured (line_assembly
harsh, seed 3): 21 of 82 calls a sample, the approach, descend and lift of the second candidate
slot's cycle (``line.slot_choice``) and the capacity estimate's.

Choices left open here: ``MARGIN`` = 1.15 over the model's bound (the model is an ideal tracker of
the error dynamics; the runs measured peaks within 7 % of it, docs/pick_place.md "Checks before
and during the run", and the torque bound sits on the unmodelled contact and grip loads);
``SHORTEST`` = 0.05 s, the floor of a way that asks nothing (a zero error).  ``TORQUE_SHARE`` =
2/3: the model plans to two thirds of each effort limit, the headroom for what the controller
side does not know — the model is the nominal arm, and the inverse dynamics is linear in the
mass parameters, so an arm whose links weigh up to 1.5 × their nominal (the robust study's
declared range, ``studies.robust.RANGES``) holding at most the rated payload (a line plans
every held part at it, ``held_mass``) asks at most 1.5 × the model's torque; the feedback's own demand
comes on top, inside ``MARGIN``.  Measured on the harsh line study (line_assembly, 50 samples,
docs/pick_place.md "The harsh study"): at the full limits the runaways were heavy parts on arms
×1.2–1.46 — seed 7 (×1.20, a 0.96 kg cube): its lift, planned at 0.19 s, was commanded 5.5 × joint
2's limit and the arm ran into the belts; at 2/3 that lift takes 0.25 s, its commands peak at
1.8 × briefly (0.5 % of the run at a limit) and the arm runs on.
``SPEED_SHARE`` = 1: a joint's speed |J⁺ẋ| is kinematic (no mass in it) — the runaways measured
were torque-led, the speeds beyond their limits came after the torques saturated.
``TRACKING`` = 10: a phase lasts at least that many time constants of the controller's velocity
loop along its way (``run_warnings.loop_inertia`` / ``gain``, the payload held; before ``MARGIN``):
the limits bound the planned motion, not the model-free feedback that follows it.  Measured on a
line of each heavier arm (docs/pick_place.md "A phase the controller tracks"): at 10, every part
placed on the Panda and the UR5e with commands within 0.57 of the limits; at 6 the Panda's commands
reached 9.5 × a limit; with the limits alone (the RV-M1's 2.7 ms loop never sets a phase) none.

``cycle_time`` — one pick cycle from the min tfs: the approach from the last place's retreat point
to ``clearance`` above a part riding its belt, the descend, the close dwell, the lift, the carry to
``lift_height`` above the place, the place, the open dwell and the retreat, each phase's way
starting where the previous one ended (the straight way: a via, ``route``, shares its phase's
tf); ``Cycle.capacity`` = 60 / cycle, picks per minute, and ``capacity`` of a sequence of cycles
(``task_cycles``: a scenario's tasks one after the other).
``held_mass`` — the mass the model plans a held part at (a line's: the arm's rated payload).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import numpy as np

from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.config.pick import PHASES, PickTaskConfig
from ptint_drake.systems.hand.datasheets import RATED_PAYLOAD
from ptint_drake.robot.plant import effort_limits, nominal_plant
from ptint_drake.systems.task.orientation import tool_yaw
from ptint_drake.verdict.run_warnings import SPEED_SAMPLES, joint_demand, joint_terms_of, loop_inertia
from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.feasibility import Way, way_motion, way_postures, way_profile
from ptint_drake.worlds.pick.route import nearest_branch, turn_ways
from ptint_drake.worlds.pick.scene import AddGripper
from ptint_drake.worlds.pick.station import MakePickStation
from ptint_drake.worlds.pick.tasks import place_target
from ptint_drake.worlds.pick.ways import nominal

MARGIN = 1.15  # over the model's shortest tf (module docstring)
TORQUE_SHARE = 2.0 / 3.0  # of each effort limit the model plans to (module docstring)
SPEED_SHARE = 1.0  # of each joint-speed limit the model plans to (module docstring)
SHORTEST = 0.05  # s: the floor of a way that asks nothing
TRACKING = 10.0  # the controller's slowest velocity-loop time constants a phase lasts at least (docstring)
TOLERANCE = 0.002  # s: a riding target's fixed point
ITERATIONS = 5
COARSE = 11  # samples of a profile, the coarser option (``PhaseTimes.samples``; default 21)
CACHE_SIZE = 4096  # ways whose postures are kept


class NoTfFits(ValueError):
    """No tf fits the phase: its message names why (no top-down posture along the way, or a limit
    the way exceeds however long it takes: gravity, or the belt's speed alone)."""


@dataclass
class PhaseTimes:
    """The feasibility model of one station for ``min_tf``: the arm's model (inverse kinematics),
    the station's plant (inverse dynamics: the arm with its gripper), the limits and the
    controller's weighing and damping, and the cache of the ways' postures."""

    arm: object
    frame: object
    plant: object
    tool: object
    instance: object
    q0: np.ndarray
    speed_limits: np.ndarray
    effort_limits: np.ndarray
    rot_scale: float = 1.0
    damping: float = 0.0
    gripper_speed: float = 0.05  # m/s per jaw: a descend is at least the fingers' close (``cycle_time``)
    gain: float = 50.0  # the controller's K (eq. 18): a phase lasts ``TRACKING`` of its loop's time constants
    samples: int = SPEED_SAMPLES  # of each profile (``COARSE``: fewer, faster)
    torque_share: float = TORQUE_SHARE  # of the effort limits planned to
    speed_share: float = SPEED_SHARE  # of the joint-speed limits planned to
    postures: dict = field(default_factory=dict)
    last: float = 1.0  # s: the last riding phase's tf, the next one's first guess
    answers: dict = field(default_factory=dict)  # a call's bits → (tf, ``last`` after it): ``min_tf``

    @classmethod
    def of(cls, scenario) -> "PhaseTimes":
        """The model of a pick scenario's station (its robot, gripper and controller settings)."""
        station = MakePickStation(world_config(scenario))
        plant = station.plant
        arm = nominal_plant(scenario)
        nv = plant.num_velocities()
        cols = plant.GetVelocitiesFromArray(station.arm, np.arange(nv, dtype=float)).astype(int)
        return cls(arm, arm.GetFrameByName(scenario.robot.end_effector), plant,
                   plant.GetFrameByName(scenario.robot.end_effector, station.arm), station.arm,
                   np.radians(scenario.robot.initial_q_deg), plant.GetVelocityUpperLimits()[cols],
                   effort_limits(arm), scenario.controller.rot_scale, scenario.controller.pinv_damping,
                   scenario.pick.gripper.speed, scenario.controller.K)

    def min_tf(self, start, target, velocity=None, payload: float = 0.0, beta: float = 0.75,
               yaws: tuple = (0.0, 0.0), q: Optional[np.ndarray] = None, margin: float = MARGIN) -> float:
        """The shortest tf (s) of a phase from the tool point ``start`` to ``target`` (where it is
        at the phase's start; riding at ``velocity``, m/s, default at rest), holding ``payload``
        (kg), with TBG shape ``beta``, the tool turning from yaw ``yaws[0]`` to ``yaws[1]`` (rad; a
        near-quarter turn either way round, the slower: ``route.turn_ways``),
        the postures solved from ``q`` (default: the start posture), times ``margin`` (module
        docstring; a call asked again: its first answer).  ``NoTfFits`` names why none does."""
        riding = velocity is not None and bool(np.any(velocity))
        bits = (start, target, velocity, self.q0 if q is None else q, *self.limits())
        key = tuple(None if v is None else np.asarray(v, dtype=float).tobytes() for v in bits) \
            + (float(payload), float(beta), tuple(map(float, yaws)), float(margin),
               self.last if riding else None, self.samples, self.rot_scale, self.damping)
        if key not in self.answers:
            tf = self._min_tf(start, target, velocity, payload, beta, yaws, q, margin)
            if len(self.answers) >= CACHE_SIZE:
                self.answers.pop(next(iter(self.answers)))
            self.answers[key] = (tf, self.last if riding else None)
        tf, last = self.answers[key]
        self.last = self.last if last is None else last
        return tf

    def _min_tf(self, start, target, velocity, payload: float, beta: float, yaws: tuple,
                q: Optional[np.ndarray], margin: float) -> float:
        """``min_tf``, computed: the slower of the ways the tool may turn (``route.turn_ways``: a
        near-quarter turn either way round; ``NoTfFits`` where either has none)."""
        return max(self._min_tf_way(_way(start, target, velocity, payload, ways), q, beta, margin)
                   for ways in turn_ways(yaws))

    def _min_tf_way(self, way: Way, q: Optional[np.ndarray], beta: float, margin: float) -> float:
        """``_min_tf`` of one way."""
        guess = self.q0 if q is None else np.asarray(q, dtype=float)
        if not np.any(way.ride):  # a fixed target: its way does not depend on tf
            return margin * self._shortest(way, self._postures(way, 1.0, beta, guess), beta)
        tried, found = [], []  # the fixed point tf = shortest(way at tf), by the secant method
        tf = self.last
        for _ in range(ITERATIONS):
            tried.append(tf)
            found.append(self._shortest(way, self._postures(way, tf, beta, guess), beta))
            if abs(found[-1] - tf) < TOLERANCE:
                self.last = found[-1]
                return margin * found[-1]
            tf = found[-1]
            if len(tried) > 1:
                h0, h1 = found[-2] - tried[-2], found[-1] - tried[-1]
                if h1 != h0:
                    tf = max(tried[-1] - h1 * (tried[-1] - tried[-2]) / (h1 - h0), SHORTEST)
        return margin * max(found[-1], found[-2])

    def demand(self, start, target, tf: float, velocity=None, payload: float = 0.0, beta: float = 0.75,
               yaws: tuple = (0.0, 0.0), q: Optional[np.ndarray] = None) -> float:
        """The feasibility check of a phase taken in ``tf`` s (the arguments of ``min_tf``): the
        largest ratio of a joint's speed or torque to its limit along the whole profile
        (``feasibility.way_profile``, ``run_warnings.joint_demand``), inf where a sample has no
        top-down posture; ≤ 1 fits."""
        V, L = self.limits()
        worst, q = 0.0, self.q0 if q is None else np.asarray(q)
        for ways in turn_ways(yaws):  # (a near-quarter turn: either way round, the worse)
            way = _way(start, target, velocity, payload, ways)
            profile = way_profile(self.arm, self.frame, way, tf, beta, q)
            if profile is None:
                return float("inf")
            speeds, torques = joint_demand(self.plant, self.tool, profile, self.instance, self.rot_scale,
                                           self.damping)
            worst = max(worst, float(max(np.max(speeds / V), np.max(torques / L))))
        return worst

    def initial_yaw(self) -> float:
        """rad: the tool's yaw at the initial posture ``q0``."""
        context = self.arm.CreateDefaultContext()
        self.arm.SetPositions(context, self.q0)
        return float(tool_yaw(self.frame.CalcPoseInWorld(context).rotation().matrix()))

    def limits(self) -> tuple:
        """(joint speeds, rad/s; torques, N·m): the shares of the arm's limits the model plans to
        (``speed_share``, ``torque_share``; module docstring)."""
        return self.speed_share * self.speed_limits, self.torque_share * self.effort_limits

    def _postures(self, way: Way, tf: float, beta: float, guess: np.ndarray) -> np.ndarray:
        """``feasibility.way_postures``, cached by the way (to 0.1 mm, 1 mrad, 1 ms)."""
        key = (tuple(np.round(np.r_[way.target, way.ride, way.e0], 4)), tuple(np.round(way.yaws, 3)),
               round(beta, 4), round(tf, 3) if np.any(way.ride) else None, self.samples)
        if key not in self.postures:
            postures = way_postures(self.arm, self.frame, way, tf, beta, guess, self.samples)
            if postures is None:
                start = np.round(way.target + way.e0, 3).tolist()
                raise NoTfFits(f"no top-down posture along the way from {start} m to "
                               f"{np.round(way.target, 3).tolist()} m")
            if len(self.postures) >= CACHE_SIZE:
                self.postures.pop(next(iter(self.postures)))
                self.answers.clear()  # (an answer may have read the postures dropped)
            self.postures[key] = postures
        return self.postures[key]

    def _shortest(self, way: Way, postures: np.ndarray, beta: float) -> float:
        """The model's shortest tf on the fixed ``postures`` (module docstring: the smallest root)."""
        n = len(postures)
        rest = np.hstack([np.zeros((n, 3)), np.tile(way.ride, (n, 1))])  # u = 0: the target's motion alone
        motions = [(rest, np.zeros_like(rest))] + [way_motion(way, tf, beta, self.samples)
                                                   for tf in (1.0, 0.5)]
        (A, t0), (v1, t1), (_, t2) = joint_terms_of(self.plant, self.tool, postures, motions, way.payload,
                                                    self.instance, self.rot_scale, self.damping)
        B, c2 = v1 - A, 0.5 * (t2 - 2.0 * t1 + t0)
        c1 = t1 - t0 - c2
        V, L = self.limits()
        over = np.flatnonzero((np.abs(A) > V).any(axis=0) | (np.abs(t0) > L).any(axis=0))
        if len(over):
            j = int(over[0])
            raise NoTfFits(f"joint {j + 1} is beyond its limit however long the phase takes (gravity, or "
                           f"the target's own motion)")
        roots = [(s * V - A) / np.where(B == 0.0, np.nan, B) for s in (1.0, -1.0)]
        for s in (1.0, -1.0):
            a, b, c = c2, c1, t0 - s * L
            disc = np.sqrt(np.where(b * b - 4 * a * c >= 0.0, b * b - 4 * a * c, np.nan))
            with np.errstate(divide="ignore", invalid="ignore"):
                linear = np.where(np.abs(a) < 1e-12, -c / b, np.nan)
                roots += [np.where(np.abs(a) < 1e-12, linear, (-b + sign * disc) / (2 * a))
                          for sign in (1, -1)]
        u = np.concatenate([np.ravel(r) for r in roots])
        u = u[np.isfinite(u) & (u > 0.0)]
        tracked = TRACKING * loop_inertia(self.plant, self.tool, postures, way.payload, self.instance,
                                          self.rot_scale, self.damping) / self.gain
        return max(1.0 / float(np.min(u)) if len(u) else 0.0, tracked, SHORTEST)


def _way(start, target, velocity, payload: float, yaws: tuple) -> Way:
    """The ``feasibility.Way`` of a phase from the tool point ``start`` to ``target`` (riding at
    ``velocity``; None: at rest)."""
    target = np.asarray(target, dtype=float)
    ride = np.zeros(3) if velocity is None else np.asarray(velocity, dtype=float)
    return Way(target, ride, np.asarray(start, dtype=float) - target, tuple(map(float, yaws)), payload)


@dataclass(frozen=True)
class Cycle:
    """One pick cycle: each phase's min tf (s, ``phases``), the two dwells (s) and the total (s)."""

    phases: dict
    dwell: float
    yaws: tuple = ()  # rad: (grip, put), the tool's yaw at the grasp and at the place

    @property
    def total(self) -> float:
        """The cycle's time (s): the phases and the close and open dwells."""
        return float(sum(self.phases.values()) + 2.0 * self.dwell)

    @property
    def capacity(self) -> float:
        """Picks per minute at this cycle."""
        return 60.0 / self.total


def cycle_time(model: PhaseTimes, part, ride, place, place_yaw: float = 0.0, part_yaw: float = 0.0,
               mass: float = 0.1, task: Optional[PickTaskConfig] = None, start=None,
               yaw: Optional[float] = None, place_ride=None, begin: float = 0.0,
               grip: Optional[float] = None, put: Optional[float] = None) -> Cycle:
    """One pick cycle (module docstring) of a part whose centre is at ``part`` (m) when the
    approach starts, riding at ``ride`` (m/s), of ``mass`` (kg) and yaw ``part_yaw``, to the
    place pose ``place`` (the part's centre, m) at ``place_yaw`` (rad); the tool starts at
    ``start`` turned to ``yaw`` (default: ``clearance`` above the place, turned to its yaw: where
    the last retreat ended).  ``task``: clearance, lift height, dwell, margin and each phase's β
    (default: a task's defaults).  A descend takes at least ``margin`` / the jaws' speed: the
    fingers close in at most half of it (``tasks.check_tasks``).  ``place_ride`` (m/s; None: a
    fixed place): the place rides at that velocity from ``place`` at t = 0 (an outgoing belt,
    ``out_belt``), the approach starting at ``begin`` (s); the carry, the place and the retreat each
    aim at the place point where it is when the phase starts, riding on.  ``grip`` and ``put``
    (rad): the tool's yaw at the grasp and at the place (a line's choice by the part's symmetry,
    ``line.cycle``); default the top-down task's, the part's and then the place's yaw modulo π
    nearest the tool's."""
    task = task or PickTaskConfig()
    part, ride, place = (np.asarray(v, dtype=float) for v in (part, ride, place))
    up = lambda h: np.array([0.0, 0.0, h])  # noqa: E731
    x = place + up(task.clearance) if start is None else np.asarray(start, dtype=float)
    yaw = place_yaw if yaw is None else yaw
    grip = nearest_branch(yaw, part_yaw) if grip is None else grip
    put = nearest_branch(grip, place_yaw) if put is None else put
    beta = {p: getattr(task, p).beta for p in PHASES}
    tf = {"approach": model.min_tf(x, part + up(task.clearance), ride, 0.0, beta["approach"], (yaw, grip))}
    at = part + ride * tf["approach"]
    tf["descend"] = max(model.min_tf(at + up(task.clearance), at, ride, 0.0, beta["descend"], (grip, grip)),
                        task.margin / model.gripper_speed)
    lifted = at + ride * (tf["descend"] + task.dwell)
    tf["lift"] = model.min_tf(lifted, lifted + up(task.lift_height), None, mass, beta["lift"], (grip, grip))
    v = None if place_ride is None else np.asarray(place_ride, dtype=float)
    place_at = lambda t: place if v is None else place + v * t  # noqa: E731  (a phase starting at t)
    t = begin + tf["approach"] + tf["descend"] + task.dwell + tf["lift"]
    tf["carry"] = model.min_tf(lifted + up(task.lift_height), place_at(t) + up(task.lift_height), v, mass,
                               beta["carry"], (grip, put))
    t += tf["carry"]
    tf["place"] = model.min_tf(place_at(t) + up(task.lift_height), place_at(t), v, mass, beta["place"],
                               (put, put))
    t += tf["place"] + task.dwell
    tf["retreat"] = model.min_tf(place_at(t), place_at(t) + up(task.clearance), v, 0.0, beta["retreat"],
                                 (put, put))
    return Cycle(tf, task.dwell, (grip, put))


def held_mass(scenario, declared: float) -> float:
    """kg the model plans a held part at: the arm's rated payload less its hand's mass
    (``datasheets.RATED_PAYLOAD``), the most the arm may be asked to carry — a part's true mass is
    not known on the controller side, and a part heavier than its kind declares, run at tfs fitted
    to the declared mass, saturated the arm (the harsh line study, parts drawn up to 1.06 kg on the
    RV-M1: 4 of 10 samples, 0.63 of the parts placed, against 0.97 with the tasks' default tfs).
    Never less than the ``declared`` mass; the declared mass on an arm without a rated payload."""
    rated = RATED_PAYLOAD.get(scenario.robot.model)
    if rated is None:
        return declared
    gripper = scenario.pick.gripper
    key = (scenario.robot.model, repr(gripper))
    if key not in _HAND_KG:
        plant = MultibodyPlant(0.0)
        instance = AddGripper(plant, plant.world_frame(), gripper)
        _HAND_KG[key] = sum(plant.get_body(b).default_mass() for b in plant.GetBodyIndices(instance))
    return max(declared, rated - _HAND_KG[key])


_HAND_KG: dict = {}


def task_cycles(scenario, model: Optional[PhaseTimes] = None) -> list:
    """Per task of a pick scenario, in order: its ``Cycle`` from the min tfs, each task starting
    where and when the previous one ended (the first from the start posture at t = 0 or its
    ``start``), the parts at their nominal places riding their belts (``ways.nominal``) — what the
    scenario's tfs would be set to (``rounded_up``)."""
    model = model or PhaseTimes.of(scenario)
    world = nominal(scenario, model.arm)
    pick = scenario.pick
    names = [p.name for p in pick.parts]
    x, yaw, t, out = world.start, model.initial_yaw(), 0.0, []
    for k, task in enumerate(pick.tasks):
        t = max(t, task.start)
        j = names.index(task.part)
        p0, ride = world.parts[j]
        place_yaw = place_target(pick, task)[2]
        cycle = cycle_time(model, p0 + ride * t, ride, world.places[k], place_yaw, world.part_yaws[j],
                           pick.parts[j].mass, task, x, yaw)
        out.append(cycle)
        t += cycle.total
        x, yaw = world.places[k] + [0.0, 0.0, task.clearance], nearest_branch(nearest_branch(
            yaw, world.part_yaws[j]), place_yaw)
    return out


def capacity(cycles: list) -> float:
    """Picks per minute of ``cycles`` (``Cycle``) run one after the other: 60 · n / their total time."""
    return 60.0 * len(cycles) / sum(c.total for c in cycles)


def rounded_up(tf: float, step: float = 0.01) -> float:
    """``tf`` rounded up to ``step`` (s): a setting for a scenario."""
    return round(float(np.ceil(tf / step - 1e-9) * step), 6)


