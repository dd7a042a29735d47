"""Before a pick run: do the fingers keep clear of the belts on the way to each part?

The approach and the descend of a task are prescribed-time interceptions of a moving target: with
the controller's design error dynamics e(t) = ξ(t) e(t0) (SPEC 2.1, ξ the time base generator ξ(τ)
= I⁻¹(1−β, 1−β; 1 − τ/tf)), the fingertip centre follows x(t) = p(t) + ξ(t) (x(t0) − p(t0)), with
p(t) the target riding its belt at the belt's nominal speed. ``check_pick_clearance`` samples that
path — the planned way of ``ways.segment_way``, the one tracer the vias and the feasibility check
follow too: the approach from the start pose, or from the previous task's retreat, to ``clearance``
above the part, by way of its via if it has one; the descend onto the part's centre — and checks
the fingers' vertical extent (from the pads' lower edge to the fingers' top, read from the
gripper's collision geometry) against each belt's slab wherever the open fingers (a disc of half
the opening plus the finger's thickness) are over it. A pass into a belt, or less than
``MIN_CLEARANCE`` above it, is a one-line ScenarioError naming the field to change (exit 2), as is
a part wider than the gripper's stroke less its task's margin (``check_pick_opening``). The links
above the hand are not checked here: their contacts are found during the run (``collisions``).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.systems.hand.datasheets import payload_warnings
from ptint_drake.worlds.pick.config import grasp_width
from ptint_drake.worlds.pick.feasibility import feasibility_warnings
from ptint_drake.worlds.pick.obstacles import obstacle_warnings
from ptint_drake.worlds.pick.scene import FINGER_JOINTS, belt_frame, finger_extent
from ptint_drake.worlds.pick.singularity import inner_reach_warnings, singularity_warnings
from ptint_drake.worlds.pick.tasks import VIA_PART
from ptint_drake.worlds.pick.ways import nominal, segment_way

MIN_CLEARANCE = 0.001  # m: the least gap wanted between the fingers and a belt's top surface
SAMPLES = 60  # points along each checked segment


def check_pick_clearance(scenario, built) -> None:
    """ScenarioError when a task's approach or descend takes the fingers into a belt (module
    docstring); ``built``: a ``run.PickBuilt``."""
    station, plan = built.station, built.plan
    config = station.config
    reach, top, thickness = finger_extent(station.plant, station.scene_graph, station.gripper)
    stroke = sum(station.plant.GetJointByName(n, station.gripper).position_upper_limits()[0]
                 for n in FINGER_JOINTS)
    check_pick_opening(scenario, stroke)
    world = nominal(scenario, built.arm)
    for k, task in enumerate(scenario.pick.tasks):
        i_part = plan.segments[plan.segment_index(k, "approach")].index
        radius = min(grasp_width(config.parts[i_part]) + task.margin, stroke) / 2 + thickness
        approach_field = "robot.initial_q_deg" if k == 0 else f"pick.tasks[{k}].clearance"
        via = [i for i, s in enumerate(plan.segments) if s.task == k and s.kind == VIA_PART]
        checked = [(i, approach_field, "via") for i in via[:1]]  # the way around the base (route)
        checked += [(plan.segment_index(k, "approach"), approach_field, "approach"),
                    (plan.segment_index(k, "descend"), f"pick.parts[{i_part}].size", "descend")]
        for i, field, phase in checked:
            seg = plan.schedule.segments[i]
            tau = np.linspace(0.0, seg.tf, SAMPLES)
            path = segment_way(world, plan, i, tau)
            for b in config.belts:
                _check_belt(b, path, seg.start + tau, reach, top, radius, field, k, phase)


def check_pick_opening(scenario, stroke: float) -> None:
    """ScenarioError naming ``pick.parts[i].size`` when a task's part is wider than the gripper's
    ``stroke`` (m) less the task's ``margin``: the fingers cannot open the margin around it, so they
    would reach it before the prescribed time (an early grasp), or land on it."""
    names = [p.name for p in scenario.pick.parts]
    for k, task in enumerate(scenario.pick.tasks):
        i = names.index(task.part)
        width = grasp_width(scenario.pick.parts[i])
        if width + task.margin > stroke + 1e-12:
            need, most = width + task.margin, stroke - task.margin
            raise ScenarioError(f"pick.parts[{i}].size: {width:g} m across the fingers plus "
                                f"pick.tasks[{k}].margin {task.margin:g} m needs an opening of {need:.4g} m, "
                                f"beyond the gripper's {stroke:g} m stroke (a part at most {most:.4g} m "
                                f"wide, or a smaller margin)")


def _check_belt(belt, path: np.ndarray, t: np.ndarray, reach: float, top: float, radius: float,
                field: str, k: int, phase: str) -> None:
    X = belt_frame(belt)
    R = X.rotation().matrix()
    slide = np.outer(t, belt.speed * np.asarray(belt.direction, dtype=float))
    local = (path - X.translation() - slide) @ R  # in the belt's frame (its top-surface centre)
    over = ((np.abs(local[:, 0]) <= belt.length / 2 + radius)
            & (np.abs(local[:, 1]) <= belt.width / 2 + radius))
    low, high = local[:, 2] - reach, local[:, 2] + top  # the fingers' vertical extent
    hit = over & (low < MIN_CLEARANCE) & (high > -belt.thickness)
    if np.any(hit):
        i = int(np.flatnonzero(hit)[np.argmin(low[hit])])  # the deepest point
        depth = 1e3 * (MIN_CLEARANCE - low[i])
        raise ScenarioError(f"{field}: task {k}'s {phase} takes the fingers {depth:.1f} mm "
                            f"into the clearance of belt {belt.name!r} at t = {t[i]:.2f} s (keep them "
                            f"≥ {1e3 * MIN_CLEARANCE:g} mm above it)")


def arm_warnings(scenario, built) -> list[str]:
    """Warnings before a pick run about the arm: the gripper plus a part beyond the arm's rated
    payload (``grippers.payload_warnings``), a path past a singularity or near the inner edge of a
    5-joint arm's top-down workspace (``singularity``), a segment too short for a joint's speed or
    effort limit along its planned profile (``feasibility``), a way the hand still sweeps through an
    obstacle after the vias (``obstacles``)."""
    station = built.station
    plant = station.plant
    gripper_kg = sum(plant.get_body(b).default_mass() for b in plant.GetBodyIndices(station.gripper))
    return (payload_warnings(scenario.robot.model, station.config.gripper.model, gripper_kg,
                             station.config.parts) + singularity_warnings(scenario, built)
            + inner_reach_warnings(scenario, built) + feasibility_warnings(scenario, built)
            + obstacle_warnings(scenario, nominal(scenario, built.arm), built.plan))
