"""The pick cell as its scenario declares it: what the simulated station and the controller side
both build from, so that the controller side needs no station — the world's configuration
(``world_config``: the robot, the plant settings, the belts, the parts as placed, the tray), the
slots' place positions from the declared tray (``place_positions``) and a run's logging periods
(``PROBE_PERIOD``, ``REPLAY_PERIOD``: ``ptint run`` logs at them, and the drive's controller side
takes its sample times there too, so that its integration splits where the run's does).
"""

from __future__ import annotations

import numpy as np

from ptint_drake.config.schema import Scenario
from ptint_drake.config.part_shape import part_height
from ptint_drake.worlds.pick.config import DEFAULT_APPROXIMATION, PickWorldConfig
from ptint_drake.worlds.pick.placement import placed_parts
from ptint_drake.worlds.pick.scene import belt_frame, bin_drop, slot_pose
from ptint_drake.worlds.pick.tasks import PLACES, PickPlan

PROBE_PERIOD = 0.002  # s, between logged probe samples
REPLAY_PERIOD = 1.0 / 30.0  # s, between logged whole-plant states (the replay's frames)


def world_config(scenario: Scenario) -> PickWorldConfig:
    """The pick world of a scenario: its robot, its ``multibody`` plant settings (default: 1 ms,
    point contact, SAP) and its ``pick`` block."""
    mb, p = scenario.multibody, scenario.pick
    seed = scenario.measurement.seed if scenario.measurement is not None else 0
    config = PickWorldConfig(model=scenario.robot.model, end_effector=scenario.robot.end_effector,
                             initial_q_deg=list(scenario.robot.initial_q_deg), gripper=p.gripper,
                             belts=p.belts, parts=placed_parts(p.parts, seed), tray=p.tray,
                             bins=p.bins)
    if mb is not None:
        config.time_step = mb.time_step
        config.contact_approximation = mb.discrete_contact_approximation or DEFAULT_APPROXIMATION
        config.contact_model = mb.contact_model
    return config


def place_point(config, kind: str, index: int, part, along: float = 0.0) -> np.ndarray:
    """The place pose of ``part`` (its centre, world, m) at slot ``index`` (``kind`` "slot": resting
    on the tray, ``scene.slot_pose``: the pose the station's ``slot_k`` frame is welded at), over
    bin ``index`` ("bin": ``scene.bin_drop``) or on belt ``index`` ("belt": resting on its top on its
    centre line, ``along`` m along it — at t = 0: the point rides on, ``tasks.place_ride``);
    ``config``: a ``PickWorldConfig`` or a ``pick`` block."""
    if kind == "bin":
        return bin_drop(config.bins[index], part)
    height = part_height(part.shape, part.size)
    if kind == "belt":
        return belt_frame(config.belts[index]).multiply(np.array([along, 0.0, height / 2]))
    return slot_pose(config.tray, index).translation() + [0.0, 0.0, height / 2]


def place_positions(config: PickWorldConfig, plan: PickPlan) -> list:
    """Per segment: the world position of its slot's place pose (the part's centre resting on the
    tray; a bin's drop point, ``scene.bin_drop``; an outgoing belt's place point at t = 0), None
    for the segments that aim at a part — from the declared tray, slots, bins and belts alone
    (``place_point``), so the controller side needs no station to find them."""
    out = []
    for seg in plan.segments:
        if seg.kind not in PLACES:
            out.append(None)
            continue
        part = config.parts[plan.segments[plan.segment_index(seg.task, "approach")].index]
        out.append(place_point(config, seg.kind, seg.index, part, seg.along))
    return out
