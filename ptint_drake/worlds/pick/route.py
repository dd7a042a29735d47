"""The way around the arm's base: a via point where a pick's straight way passes too near the
waist axis.

Near its own waist axis an arm cannot point its tool down: no top-down posture within the joint
limits exists closer than an *inner edge* (rvm1_5dof: about 85 mm from the axis at z = 0.15-0.19
m, where its wrist pitch meets its −90° limit; rvm1_6dof: 75-85 mm), and the task's Jacobian
loses rank on the way there (issue 33: ``tests/two_belt_pick_mirrored.yaml``'s second approach,
from a tray at y = −0.24 m to a part on the +y side, passed 106 mm from the axis on rvm1_5dof,
slid into the edge and missed).  A prescribed-time segment follows its error dynamics
e(t) = ξ(t) e(t0) (SPEC 2.1): towards a fixed target a straight line, towards a part riding its
belt a straight line relative to the part.  ``nominal_paths`` samples every segment's way so,
from the start posture's tool point, with the parts at their nominal places on their belts and
the slots where the tray puts them (configuration and the arm's kinematics only).

``plan_vias`` looks at each task's first approach and its carry: where the way comes within
``INNER_MARGIN`` of the inner edge (``too_near``: no top-down posture ``INNER_MARGIN`` nearer the
axis than the way's nearest point, Drake's ``InverseKinematics`` within the joint limits), the
phase is split (``tasks.Via``) at a fixed point on the far side of its nearest point: on the ray
from the axis through that point, at the height of that point, at the smallest radius (from the
edge + ``INNER_MARGIN`` outwards in ``VIA_STEP`` steps) where a top-down posture exists and both
legs keep ``INNER_MARGIN`` clear of the edge.  The via's leg takes the share of the phase's tf
that its length takes of the two legs' (the same mean speed on both), so every prescribed time
after it stays where the scenario put it.  The edge itself is found by bisection along the ray
(``inner_edge``).  Where no radius clears, no via is made and ``singularity.inner_reach_warnings``
warns before the run.  ``routed_plan`` is the plan with its vias: what the run, the drive and the
schedule use.  Planning uses the arm's kinematic model; at run time the via is a fixed target
like a slot (``targets.PickTargets``): the controller stays model-free.

A carry may also get a via halfway along it for the way its wrist turns (``_carry_turn``): the
top-down task turns the tool to the slot's top-down yaw nearest its own (modulo π), and that way
may take the wrist's roll past its joint limit (``tests/two_belt_pick_mirrored.yaml`` after the
route: the block grasped at tool yaw 155°, the nearer branch of the slot's 60° is 240°, which
needs rvm1_5dof's roll at −217°: it stopped at −180°, the block placed 36.8° off).  A
joint-space continuation of the carry (IK from sample to sample, ``TURN_SAMPLES``) finds where it
breaks; the via, turned halfway towards the other branch, makes the wrist turn the other way.

Only arms with fewer than ``FULL_TOP_DOWN`` joints get vias (``rvm1_5dof``: a 5-D top-down task
by design, its inner edge its wrist pitch's limit).  On ``rvm1_6dof`` the
same test finds the same ways too near (its inner edge is at 75-85 mm as well), but measured with
the vias it missed both two-belt scenarios (the via and the approach reached their targets, then
the mirrored one's descend ended 11.6 mm and 18° off, and collisions followed; cause not
isolated), and without them it places every part of both (docs/pick_place.md).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.worlds.pick.obstacles import obstacle_vias
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.worlds.pick.tasks import PLACES, VIA_PART, VIA_SLOT, PickPlan, Via, aimed_yaw, pick_plan
from ptint_drake.worlds.pick.ways import Nominal, down_posture, nominal, nominal_paths

INNER_MARGIN = 0.04  # m: a way closer than this to the inner edge of the top-down workspace is too near
VIA_STEP = 0.005  # m: the via's radius is searched in these steps
EDGE_TOLERANCE = 0.002  # m: the inner edge's bisection stops at this width
ROUTED = ("approach", "carry")  # the phases a via may split (the first attempt's approach)
TURN_SAMPLES = 9  # samples of a carry's joint-space continuation
FULL_TOP_DOWN = 6  # joints: an arm with as many has no via (module docstring)
JUMP = np.radians(60.0)  # rad: a joint moving more than this between two samples breaks a continuation
TURN_DOUBT = np.radians(10.0)  # rad: a turn this near a quarter turn may go either way (``turn_ways``)


def _nearest(world: Nominal, path: np.ndarray) -> tuple:
    """(radius from the waist axis, the point) of a way's sample nearest the axis."""
    radius = np.hypot(*(path[:, :2] - world.axis).T)
    i = int(np.argmin(radius))
    return float(radius[i]), path[i]


def _at(world: Nominal, point: np.ndarray, radius: float) -> np.ndarray:
    """``point`` moved along its ray from the waist axis to ``radius``."""
    d = point[:2] - world.axis
    n = np.linalg.norm(d)
    u = d / n if n > 1e-9 else np.array([1.0, 0.0])
    return np.array([*(world.axis + radius * u), point[2]])


def too_near(world: Nominal, path: np.ndarray) -> tuple:
    """(radius, nearest point) of a way that passes within ``INNER_MARGIN`` of the inner edge (no
    top-down posture ``INNER_MARGIN`` nearer the axis than its nearest point, solved from the start
    posture or else from the nearest point's own: from the start posture alone the solver missed
    postures that exist, e.g. 98 mm from the axis at an azimuth of −25°, the edge there at 85 mm),
    else None."""
    radius, point = _nearest(world, path)
    if radius <= INNER_MARGIN:
        return radius, point
    inner = _at(world, point, radius - INNER_MARGIN)
    if down_posture(world, inner) is not None:
        return None
    own = down_posture(world, point)
    if own is not None and down_posture(world, inner, own) is not None:
        return None
    return radius, point


def inner_edge(world: Nominal, point: np.ndarray, far: float = 0.6) -> float:
    """The radius along ``point``'s ray (at its height) inside which no top-down posture exists:
    bisection to ``EDGE_TOLERANCE`` between the axis and the first radius (from the point's own,
    outwards in ``VIA_STEP`` steps, up to ``far``) that has one; ``far`` if none has."""
    hi = max(_nearest(world, point[None])[0], VIA_STEP)
    q = down_posture(world, _at(world, point, hi))
    while q is None and hi < far:
        hi += VIA_STEP
        q = down_posture(world, _at(world, point, hi))
    if q is None:
        return far
    lo = 0.0
    if down_posture(world, _at(world, point, lo), q) is not None:
        return 0.0
    while hi - lo > EDGE_TOLERANCE:
        mid = 0.5 * (lo + hi)
        solution = down_posture(world, _at(world, point, mid), q)
        if solution is None:
            lo = mid
        else:
            hi, q = mid, solution
    return hi


def _via_for(world: Nominal, pick, replans: tuple, vias: tuple, k: int, phase: str, i: int,
             plan: PickPlan, path: np.ndarray):
    """The ``Via`` that takes segment i (task k's ``phase``) around the base, or None (none clears)."""
    _, point = _nearest(world, path)
    safe = inner_edge(world, point) + INNER_MARGIN
    start, end = path[0], path[-1]
    for radius in np.arange(safe, safe + 0.5, VIA_STEP):
        via = _at(world, point, radius)
        if down_posture(world, via) is None:
            continue
        first, second = np.linalg.norm(via - start), np.linalg.norm(end - via)
        candidate = Via(k, phase, tuple(float(c) for c in via), float(first / (first + second)))
        trial = pick_plan(pick, replans, vias + (candidate,))
        j = next(n for n, s in enumerate(trial.segments) if s.task == k and s.phase == "via"
                 and (s.kind == VIA_PART) == (phase == "approach"))
        legs = nominal_paths(world, trial)[j:j + 2]
        if all(_nearest(world, leg)[0] >= safe - 1e-9 for leg in legs):
            return candidate
    return None


def nearest_branch(yaw: float, target: float) -> float:
    """The top-down branch of ``target`` (rad, modulo π) nearest ``yaw``: where the task turns the tool."""
    return float(target + np.pi * np.rint((yaw - target) / np.pi))


def turn_ways(yaws: tuple) -> list:
    """The ways (start, end yaw; rad) the top-down task may turn the tool from ``yaws[0]`` to the
    branch ``yaws[1]``: that way, and where the turn is within ``TURN_DOUBT`` of a quarter turn,
    the other way round too.  The task turns to its target's branch (modulo π) nearest the tool's
    *actual* yaw when a segment starts (``orientation.top_down_of``), and a tool a few degrees off
    the planned yaw (the part's estimate, the grasp's tracking) takes a near-quarter turn either
    way: harsh line_assembly's first carries planned +90° (the wrist's roll 5°) ran the roll
    beyond its speed limit in 5 of 12 samples (4.3–5.1 rad/s against 4): turned −90°, the roll
    176° (seed 13: from −30° to 145.6°)."""
    start, end = (float(y) for y in yaws)
    turn = end - start
    if abs(abs(turn) - 0.5 * np.pi) < TURN_DOUBT:
        return [(start, end), (start, end - float(np.copysign(np.pi, turn)))]
    return [(start, end)]


def tool_yaws(world: Nominal, plan: PickPlan) -> list:
    """Per segment: the tool's yaw (rad, unwrapped) at its start and at its end, as the top-down
    task turns it: to the branch (modulo π) of the target's yaw nearest the tool's yaw
    (``orientation.top_down_of``), from the start posture's, with the parts at their nominal yaws
    (a task's chosen grip: turned by their symmetry, ``tasks.aimed_yaw``)."""
    context = world.arm.CreateDefaultContext()
    world.arm.SetPositions(context, world.q0)
    R = world.frame.CalcPoseInWorld(context).rotation().matrix()
    yaw, out = float(np.arctan2(R[1, 0], R[0, 0])), []
    for seg in plan.segments:
        target = seg.yaw if seg.kind in (*PLACES, VIA_SLOT) else world.part_yaws[seg.index]
        if seg.kind in ("part", "latched", "bin", VIA_PART):  # (a chosen grip: ``tasks.aimed_yaw``)
            target = aimed_yaw(target, seg.grip)
        end = nearest_branch(yaw, target)
        out.append((yaw, end))
        yaw = end
    return out


def _turns(world: Nominal, points: np.ndarray, yaws: np.ndarray, q: np.ndarray):
    """The last posture of a joint-space continuation (Drake's ``InverseKinematics``, each sample
    from the previous one's posture) of the top-down tool at ``points`` turned to ``yaws``, or
    None where it breaks (no posture within the joint limits, or a joint jumps more than
    ``JUMP``: the wrist's roll at its limit, the way it turns)."""
    for x, yaw in zip(points, yaws):
        c, s = np.cos(yaw), np.sin(yaw)
        R = np.array([[c, s, 0.0], [s, -c, 0.0], [0.0, 0.0, -1.0]])  # Rz(yaw)·Rx(π)
        solution = inverse_kinematics(world.arm, world.frame, x, q, R=R)
        if solution is None or np.max(np.abs(solution - q)) > JUMP:
            return None
        q = solution
    return q


def _carry_turn(world: Nominal, plan: PickPlan, pick, replans: tuple, vias: tuple, k: int):
    """A ``Via`` halfway along task k's carry that turns the tool the other way round (to the slot's
    other top-down branch) where the way the top-down task turns it breaks (``_turns``) and the
    other way does not; None otherwise (module docstring)."""
    i = plan.segment_index(k, "carry")
    if plan.segments[i - 1].phase == "via":
        return None
    yaws, path = tool_yaws(world, plan)[i], nominal_paths(world, plan)[i]
    start, end = path[0], path[-1]
    q = down_posture(world, start)
    if q is None:
        return None
    s = np.linspace(0.0, 1.0, TURN_SAMPLES)[:, None]
    if _turns(world, start + s * (end - start), yaws[0] + s[:, 0] * (yaws[1] - yaws[0]), q) is not None:
        return None
    turn = yaws[1] - yaws[0]
    other = turn - np.pi * np.sign(turn)  # the other branch, turning the other way round
    middle, half = 0.5 * (start + end), yaws[0] + 0.5 * other
    q = _turns(world, start + s * (middle - start), yaws[0] + s[:, 0] * (half - yaws[0]), q)
    if q is None or _turns(world, middle + s * (end - middle), half + s[:, 0] * (yaws[0] + other - half),
                           q) is None:
        return None
    return Via(k, "carry", tuple(float(c) for c in middle), 0.5, float(half))


def plan_vias(scenario, world: Nominal, replans: tuple = ()) -> tuple:
    """The ``Via`` of every task's first approach and carry whose way is ``too_near`` the inner
    edge and can be taken around it, and of every carry whose wrist turns into a joint limit and
    can turn the other way round (module docstring)."""
    pick, vias = scenario.pick, ()
    if world.arm.num_velocities() >= FULL_TOP_DOWN:
        return vias
    plan = pick_plan(pick, replans)
    paths = nominal_paths(world, plan)
    for i, seg in enumerate(plan.segments):
        if seg.phase not in ROUTED or seg.attempt != 0 or too_near(world, paths[i]) is None:
            continue
        via = _via_for(world, pick, replans, vias, seg.task, seg.phase, i, plan, paths[i])
        if via is not None:
            vias += (via,)
    for k in range(len(pick.tasks)):
        via = _carry_turn(world, pick_plan(pick, replans, vias), pick, replans, vias, k)
        if via is not None:
            vias += (via,)
    return vias


def routed_vias(scenario, world: Nominal, replans: tuple = ()) -> tuple:
    """The plan's vias: around the base (``plan_vias``), then above what is in the way
    (``obstacles.obstacle_vias``)."""
    return obstacle_vias(scenario, world, replans, plan_vias(scenario, world, replans))


def routed_plan(scenario, replans: tuple = (), arm=None) -> PickPlan:
    """The scenario's plan with the ``replans`` a run decided and its vias (``plan_vias``); ``arm``:
    the arm's model alone (default ``robot.nominal_plant``)."""
    if arm is None:
        from ptint_drake.robot.plant import nominal_plant  # noqa: PLC0415

        arm = nominal_plant(scenario)
    return pick_plan(scenario.pick, replans, routed_vias(scenario, nominal(scenario, arm), replans))
