"""Can the gripper hold this part at all?  The friction bound of a two-finger grasp, judged from
the truth (what a study drew), so that a study counts the parts no controller could lift apart
from the picks that failed (issue 44: "parts that physically cannot be held").

Two pads squeeze the part with the finger drive's force limit F (``pick.gripper.max_force``, N
per finger); the friction of the pair is Drake's combination μ = 2 μ_pad μ_part / (μ_pad +
μ_part) (``scene``), μ_pad read from the gripper model's ``pad`` collision geometries.  Friction
holds the part up during the lift while 2 μ F ≥ m (g + a_lift), a_lift the lift segment's peak
upward acceleration: ``lift_height`` × the largest |ξ̈| of its time base generator (SPEC 2.1;
ξ goes 1 → 0 over the segment's tf with its β; β < ½ is taken as ½, where ξ̈ is unbounded at the
start).  The carry's horizontal accelerations and a pad's tilt are not in the bound: it is a
necessary condition (a part that fails it cannot be held), not a sufficient one.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from pydrake.geometry import Role, SceneGraph
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import CalcContactFrictionFromSurfaceProperties, CoulombFriction, MultibodyPlant

from ptint_drake.config.pick import GripperConfig, MoveConfig, PickTaskConfig
from ptint_drake.systems.task.tbg import tbg_profile

G = 9.81  # m/s², gravity
PAD = "pad"  # the name of the pads' collision geometries in the bundled grippers
SAMPLES = 2001  # of the lift's profile, for its peak acceleration


@lru_cache(maxsize=None)
def pad_friction(model: str) -> float:
    """The static friction of the gripper model's pads (the smallest, if they differ)."""
    from ptint_drake.worlds.pick.scene import gripper_path  # noqa: PLC0415

    plant = MultibodyPlant(0.0)
    scene_graph = SceneGraph()
    plant.RegisterAsSourceForSceneGraph(scene_graph)
    Parser(plant).AddModels(str(gripper_path(model)))
    inspector = scene_graph.model_inspector()
    mus = [inspector.GetProximityProperties(g).GetProperty("material", "coulomb_friction").static_friction()
           for g in inspector.GetAllGeometryIds(Role.kProximity)
           if inspector.GetName(g).split("::")[-1] == PAD]
    if not mus:
        raise ValueError(f"gripper.model: {model!r} has no collision geometry named {PAD!r}")
    return float(min(mus))


def pair_friction(mu_a: float, mu_b: float) -> float:
    """Drake's combination of two surfaces' (static) friction coefficients, as the plant applies it."""
    pair = CalcContactFrictionFromSurfaceProperties(CoulombFriction(mu_a, mu_a), CoulombFriction(mu_b, mu_b))
    return float(pair.static_friction())


def lift_acceleration(height: float, lift: MoveConfig) -> float:
    """The lift's peak |acceleration| (m/s²): ``height`` × max |ξ̈| over its segment."""
    beta = max(float(lift.beta), 0.5)
    tau = np.linspace(0.0, lift.tf, SAMPLES)[1:-1]
    _, _, xi_dd, _ = tbg_profile(tau, lift.tf, beta)
    return float(height * np.max(np.abs(xi_dd)))


def hold_margin(mass: float, friction: float, gripper: GripperConfig, lift_height: float,
                lift: MoveConfig) -> float:
    """2 μ F / (m (g + a_lift)): ≥ 1 when friction can carry the part through the lift."""
    mu = pair_friction(pad_friction(gripper.model), friction)
    return 2.0 * mu * gripper.max_force / (mass * (G + lift_acceleration(lift_height, lift)))


def holdable(pick, part_name: str) -> bool:
    """Whether the part ``part_name`` of a pick block can be held through its task's lift (the
    first task that picks it; a part no task picks: with the default lift)."""
    part = next(p for p in pick.parts if p.name == part_name)
    task = next((t for t in pick.tasks if t.part == part_name), PickTaskConfig())
    return hold_margin(part.mass, part.friction, pick.gripper, task.lift_height, task.lift) >= 1.0
