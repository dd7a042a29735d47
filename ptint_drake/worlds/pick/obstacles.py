"""Before a pick run: does the hand keep clear of what is in its way, and where it would not, a
via above.

A planning model holds what the controller side believes (configuration only, never the
simulated world): the belts' slabs and the tray where the scenario declares them, and every part
at its nominal pose riding its belt (``ways.nominal``).  The hand is a vertical cylinder around
the open fingers (radius half the opening plus a finger's thickness, from the pads' lower edge to
the fingers' top: ``scene.finger_extent``, read from the gripper's collision geometry; a cylinder,
so the tool's yaw does not matter) and, on a carry, the held part hangs in it (its centre at the
tool point, or below it where a short part is gripped above its centre: ``config.grip_height``).
Each task's first approach and its carry are sampled along the planned way
(``ways.segment_way``, the one tracer) at most ``STEP`` apart, and at each sample Drake's
``QueryObject.ComputeSignedDistancePairwiseClosestPoints`` gives the distance of the hand (and the
held part) to every obstacle.  A sample nearer than ``HAND_MARGIN`` to an obstacle is a hit, named
by its bodies (``Hit``).  The part an approach goes to take is an obstacle of that approach too:
the way ends ``clearance`` above it (the descend then comes down onto it from above), and before
that end the hand keeps ``HAND_MARGIN`` from it — or, where the way's end itself is nearer (a tall
part, a small clearance), no nearer than the end.  Before, only a sample inside it was a hit, and
a way rising from a tray lower than the belt could graze the part's top edge: tests/low_tray_pick
with its tray at z = 0.08 m passed 1.9 mm from its own box without a via (line_short seed 18 at
8f38957 struck the cube it approached from the tray's retreat point and ran away; at 940e9c9 its
approaches from there keep 6.7–8.9 mm from their parts, and one that went inside got a via).

Where a way hits and has no via yet (``route``: the way around the base), ``obstacle_vias`` adds one
(``tasks.Via``): a fixed point above the way's start, raised from the higher of the way's two ends in
``RISE`` steps until both legs keep clear and a top-down posture reaches it, so the tool rises
first and the approach arrives from above.  A carry's via above its start keeps the tool's yaw
there (``_held_yaw``): the rise does not turn, the leg after it does.  Where no height up to
``MAX_RISE`` clears, no via is made and ``obstacle_warnings`` names the bodies before the run.
The links above the hand are not in the planning model: their contacts are found during the run
(``collisions``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from pydrake.geometry import Box, Cylinder, ProximityProperties
from pydrake.math import RigidTransform, RotationMatrix
from pydrake.multibody.plant import AddMultibodyPlantSceneGraph
from pydrake.multibody.tree import SpatialInertia
from pydrake.systems.framework import DiagramBuilder

from ptint_drake.worlds.pick.config import grasp_width, grip_height
from ptint_drake.worlds.pick.placement import nominal_parts
from ptint_drake.worlds.pick.scene import belt_frame, bin_boxes, hand_size, part_shape, slot_pose, tray_pose
from ptint_drake.worlds.pick.tasks import VIA_PART, VIA_SLOT, PickPlan, Via, aimed_yaw, pick_plan
from ptint_drake.worlds.pick.ways import Nominal, down_posture, segment_way

HAND_MARGIN = 0.003  # m: the least distance wanted between the hand (or a held part) and an obstacle
STEP = 0.005  # m: the planned ways are sampled at most this far apart
RISE = 0.01  # m: a via's height is searched in these steps
MAX_RISE = 0.3  # m: above the higher end of the way, no higher
CHECKED = ("approach", "carry")  # the phases checked (and given a via where they hit)


@dataclass(frozen=True)
class Hit:
    """The deepest sample of a way nearer an obstacle than ``HAND_MARGIN``: the task and phase,
    the time (s), the distance (m, negative: inside) and the two bodies."""

    task: int
    phase: str
    t: float
    distance: float
    bodies: tuple

    def describe(self) -> str:
        """One line naming the bodies."""
        return (f"pick {self.task}'s {self.phase} passes {1e3 * self.distance:.1f} mm from "
                f"{self.bodies[1]!r} with the {self.bodies[0]} at t = {self.t:.2f} s")


class PlanningScene:
    """The planning model (module docstring): a plant and scene graph with every part and belt as
    a free body posed per sample, the tray anchored, and one hand per radius the tasks need (the
    fingers open around a part to approach it, closed on it to carry it); the hands not in use are
    parked far below."""

    PARKED = RigidTransform([0.0, 0.0, -100.0])

    def __init__(self, scenario):
        pick = scenario.pick
        self.parts_config = nominal_parts(pick.parts)
        builder = DiagramBuilder()
        plant, scene_graph = AddMultibodyPlantSceneGraph(builder, 0.0)
        reach, top, thickness, stroke = hand_size(pick.gripper.model)
        names = [p.name for p in pick.parts]
        # a held part's centre this far below the tool point (``config.grip_height``)
        self.grip = [grip_height(p, reach) for p in pick.parts]
        self.radius = {}  # (task, phase) -> the hand's radius (m)
        for k, task in enumerate(pick.tasks):
            width = grasp_width(pick.parts[names.index(task.part)])
            self.radius[(k, "approach")] = min(width + task.margin, stroke) / 2 + thickness
            self.radius[(k, "carry")] = width / 2 + thickness
        self.hands = {}
        for r in sorted(set(self.radius.values())):
            body = plant.AddRigidBody(f"hand {r:.4f}", SpatialInertia.SolidSphereWithMass(1.0, 0.01))
            plant.RegisterCollisionGeometry(body, RigidTransform([0.0, 0.0, (top - reach) / 2]),
                                            Cylinder(r, reach + top), "hand", ProximityProperties())
            self.hands[r] = body
        self.parts = []
        for part in self.parts_config:
            body = plant.AddRigidBody(part.name, SpatialInertia.SolidSphereWithMass(1.0, 0.01))
            plant.RegisterCollisionGeometry(body, RigidTransform(), part_shape(part)[0], part.name,
                                            ProximityProperties())
            self.parts.append(body)
        self.belts = []  # (body, its pose at t = 0, its velocity): the slab rides its drive
        for belt in pick.belts:
            body = plant.AddRigidBody(f"belt {belt.name}", SpatialInertia.SolidSphereWithMass(1.0, 0.01))
            plant.RegisterCollisionGeometry(body, RigidTransform([0.0, 0.0, -belt.thickness / 2]),
                                            Box(belt.length, belt.width, belt.thickness), f"belt {belt.name}",
                                            ProximityProperties())
            d = np.asarray(belt.direction, float)
            self.belts.append((body, belt_frame(belt), belt.speed * d / np.linalg.norm(d)))
        X_T = tray_pose(pick.tray).multiply(RigidTransform([0.0, 0.0, -pick.tray.size[2] / 2]))
        plant.RegisterCollisionGeometry(plant.world_body(), X_T, Box(*pick.tray.size), "tray",
                                        ProximityProperties())
        for box in pick.bins:  # a bin's floor and walls, named by the bin
            for name, X, size in bin_boxes(box):
                plant.RegisterCollisionGeometry(plant.world_body(), X, Box(*size), f"{box.name} {name}",
                                                ProximityProperties())
        plant.Finalize()
        self.plant, self.scene_graph = plant, scene_graph
        self.diagram = builder.Build()
        self.context = self.diagram.CreateDefaultContext()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        self.sg_context = scene_graph.GetMyContextFromRoot(self.context)
        inspector = scene_graph.model_inspector()
        self.names = {}
        for g in inspector.GetAllGeometryIds():
            body = plant.GetBodyFromFrameId(inspector.GetFrameId(g))
            self.names[g] = inspector.GetName(g).split("::")[-1] if body.index() == 0 else body.name()
        self.part_ids = [set(plant.GetCollisionGeometriesForBody(b)) for b in self.parts]
        hands = {g for body in self.hands.values() for g in plant.GetCollisionGeometriesForBody(body)}
        self.obstacles = [g for g in inspector.GetAllGeometryIds() if g not in hands]

    def nearest(self, world: Nominal, tool: np.ndarray, t: float, held: "int | None", radius: float,
                only: "int | None" = None) -> tuple:
        """(distance, (mover, obstacle)) of the hand of ``radius`` at ``tool`` — and the ``held``
        part, its centre at the tool point — to the nearest obstacle (``only``: to part ``only``),
        with the parts and belts where they ride at time t."""
        self._pose(world, tool, t, held, radius)
        hand_ids = set(self.plant.GetCollisionGeometriesForBody(self.hands[radius]))
        movers = hand_ids | (self.part_ids[held] if held is not None else set())
        query = self.scene_graph.get_query_output_port().Eval(self.sg_context)
        best = (np.inf, ("hand", ""))
        # mover against obstacle only, pair by pair: the obstacles touch each other (a part resting
        # on its belt), and Drake's box-box gradient of two touching boxes fails its own check
        for mover in movers:
            for other in self.obstacles if only is None else self.part_ids[only]:
                if other in movers:
                    continue
                pair = query.ComputeSignedDistancePairClosestPoints(mover, other)
                if pair.distance < best[0]:
                    best = (pair.distance, ("hand" if mover in hand_ids else f"held {self.names[mover]}",
                                            self.names[other]))
        return best

    def _pose(self, world: Nominal, tool: np.ndarray, t: float, held: "int | None", radius: float) -> None:
        """The parts and belts where they ride at time t, the hand of ``radius`` at ``tool``."""
        set_pose = self.plant.SetFreeBodyPose
        for i, body in enumerate(self.parts):
            p0, v = world.parts[i]
            at = tool - (0.0, 0.0, self.grip[i]) if i == held else p0 + v * t
            X = RigidTransform(RotationMatrix.MakeZRotation(world.part_yaws[i]), at)
            set_pose(self.plant_context, body, X)
        for body, X0, v in self.belts:
            set_pose(self.plant_context, body, RigidTransform(X0.rotation(), X0.translation() + v * t))
        for r, body in self.hands.items():
            set_pose(self.plant_context, body, RigidTransform(tool) if r == radius else self.PARKED)


def way_hit(scene: PlanningScene, world: Nominal, plan: PickPlan, i: int) -> Hit | None:
    """The deepest hit of segment i's way (module docstring), or None when it keeps clear."""
    seg, s = plan.segments[i], plan.schedule.segments[i]
    coarse = segment_way(world, plan, i, np.linspace(0.0, s.tf, 11))
    length = float(np.sum(np.linalg.norm(np.diff(coarse, axis=0), axis=1)))
    tau = np.linspace(0.0, s.tf, max(11, int(np.ceil(2.0 * length / STEP)) + 1))
    way = segment_way(world, plan, i, tau)
    # the part a carry holds: its task's (a carry segment's own index is its slot)
    held = plan.segments[plan.segment_index(seg.task, "approach")].index if seg.phase == "carry" else None
    key = (seg.task, "carry" if seg.phase == "carry" or seg.kind == VIA_SLOT else "approach")
    worst = None
    own = HAND_MARGIN  # the part an approach goes to take: no nearer than where the way ends
    if seg.phase == "approach":
        own = min(own, scene.nearest(world, way[-1], s.end, None, scene.radius[key], seg.index)[0])
    own_name = scene.parts_config[seg.index].name if seg.phase == "approach" else None
    for k in range(len(tau)):
        d, bodies = scene.nearest(world, way[k], s.start + tau[k], held, scene.radius[key])
        limit = own if bodies[1] == own_name else HAND_MARGIN
        if d < limit and (worst is None or d < worst.distance):
            worst = Hit(seg.task, seg.phase, float(s.start + tau[k]), float(d), bodies)
    return worst


def _via_above(scene, world, pick, replans, vias, plan: PickPlan, i: int):
    """The ``Via`` above segment i's start or above its end (the lower first) that clears both
    legs, or None."""
    seg = plan.segments[i]
    start, end = segment_way(world, plan, i, np.array([0.0, plan.schedule.segments[i].tf]))
    low = max(start[2], end[2])
    held = _held_yaw(world, plan, i) if seg.phase == "carry" else None
    for z in np.arange(low + RISE, low + MAX_RISE, RISE):
        for above in (start, end):
            point = np.array([above[0], above[1], z])
            if down_posture(world, point) is None:
                continue
            first, second = np.linalg.norm(point - start), np.linalg.norm(end - point)
            share = float(first / (first + second))
            yaw = held if above is start else None  # a rise keeps the yaw it starts with
            candidate = Via(seg.task, seg.phase, tuple(float(c) for c in point), share, yaw)
            trial = pick_plan(pick, replans, vias + (candidate,))
            j = next(n for n, s in enumerate(trial.segments) if s.task == seg.task and s.phase == "via"
                     and s.kind == (VIA_PART if seg.phase == "approach" else VIA_SLOT))
            if way_hit(scene, world, trial, j) is None and way_hit(scene, world, trial, j + 1) is None:
                return candidate
    return None


def _held_yaw(world: Nominal, plan: PickPlan, i: int) -> float:
    """rad: the yaw of the part carry segment i holds — the tool's yaw at the carry's start, modulo
    π (``route.tool_yaws``: the top-down task turns to the branch of a target's yaw nearest the
    tool's), so a via turned to it does not turn.  A carry's via above its start keeps it, so that
    its short rise does not turn the wrist the whole way to the slot's yaw (the long leg after it
    does): by the legs' lengths the rise got a few per cent of the carry's tf for the whole turn."""
    approach = plan.segments[plan.segment_index(plan.segments[i].task, "approach")]
    return aimed_yaw(world.part_yaws[approach.index], approach.grip)  # (a chosen grip: turned)


def checked_segments(plan: PickPlan) -> list:
    """The indices of the segments checked: every first approach and carry."""
    return [i for i, seg in enumerate(plan.segments) if seg.phase in CHECKED and seg.attempt == 0]


def obstacle_vias(scenario, world: Nominal, replans: tuple, vias: tuple) -> tuple:
    """``vias`` and a ``Via`` above the start of every first approach and carry that hits an
    obstacle and has no via yet, where one clears (module docstring)."""
    pick = scenario.pick
    scene = PlanningScene(scenario)
    plan = pick_plan(pick, replans, vias)
    checked = [(plan.segments[i].task, plan.segments[i].phase) for i in checked_segments(plan)]
    for task, phase in checked:
        if any(v.task == task and v.phase == phase for v in vias):
            continue
        plan = pick_plan(pick, replans, vias)
        i = next(n for n, s in enumerate(plan.segments)
                 if s.task == task and s.phase == phase and s.attempt == 0)
        if way_hit(scene, world, plan, i) is None:
            continue
        via = _via_above(scene, world, pick, replans, vias, plan, i)
        if via is not None:
            vias += (via,)
    return vias


def obstacle_warnings(scenario, world: Nominal, plan: PickPlan) -> list[str]:
    """One warning per checked segment of the run's plan (its vias included) that still hits."""
    scene = PlanningScene(scenario)
    hits = [way_hit(scene, world, plan, i) for i, seg in enumerate(plan.segments)
            if (seg.phase in CHECKED and seg.attempt == 0) or seg.phase == "via"]
    return [f"{h.describe()}: no via above clears it (the hand keeps {1e3 * HAND_MARGIN:g} mm)"
            for h in hits if h is not None]


def slot_warnings(scenario, margin: float) -> list[str]:
    """One warning per tray slot of a line's catalog where the open fingers placing a part of its
    kind (the hand's cylinder of the planning model: half the opening, the kind's width +
    ``margin``, plus a finger's thickness) come within ``HAND_MARGIN`` of a belt's slab whose top is
    above the tray's (the fingers go down beside it): no via helps there, every place at that slot
    touches the belt.  Measured, line_two_belts at 8f38957: its tray's column at x = 0.17 m, the
    inner belt's edge at 0.195 m — the right finger 0.3 mm into the inner belt at the place and the
    retreat, `collision with inner` in 20 of 61 placed picks."""
    pick = scenario.pick
    thickness = hand_size(pick.gripper.model)[2]
    out = []
    for kind in pick.line.catalog:
        radius = (kind.size[0] + margin) / 2 + thickness
        for j in kind.slots:
            at = slot_pose(pick.tray, j).translation()
            for belt in pick.belts:
                local = belt_frame(belt).inverse().multiply(at)
                gap = np.hypot(max(abs(local[0]) - belt.length / 2, 0.0),
                               max(abs(local[1]) - belt.width / 2, 0.0))
                if belt.center[2] > at[2] and gap - radius < HAND_MARGIN:
                    out.append(f"pick.tray.slots[{j}]: the open fingers placing a {kind.name} there come "
                               f"{1e3 * (gap - radius):.1f} mm from belt {belt.name!r} (below its top): "
                               f"collision with {belt.name} at every place there")
    return out
