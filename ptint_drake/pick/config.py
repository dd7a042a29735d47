"""Typed settings of the pick-and-place world, loadable with Drake's ``yaml_load_typed``
(the style of ``scenario``: plain dataclasses, lists of floats, every field's unit beside it).

World frame: the arm's base frame (z up).  A *belt* is a conveyor whose top surface is a slab
riding a prismatic joint (``scene``); a *part* is a free box or cylinder resting on a belt; the
*tray* is a welded plate whose *slots* are place poses.  ``PickWorldConfig`` gathers them with
the plant's settings (Drake's ``MultibodyPlantConfig`` fields that matter here).
(No ``from __future__ import annotations`` here: ``yaml_load_typed`` reads the field types.)
"""


from dataclasses import dataclass, field
from typing import List

import numpy as np

from ptint_drake.validation import ScenarioError


@dataclass
class GripperConfig:
    """A parallel two-finger gripper welded at the arm's end-effector frame (defaults: the
    RV-M1's motor-operated hand as modelled in ``models/rvm1_gripper.sdf``; models/README.md
    gives the sources and assumptions).  The finger joints are Drake PD-controlled actuators
    (implicit in the discrete solver) whose effort limit is the grip force."""

    model: str = "rvm1_gripper"  # a bundled gripper (models/<name>.sdf) or a path to an SDFormat file
    max_force: float = 30.0  # N, per finger: the force limit (actuator effort limit)
    speed: float = 0.05  # m/s, per finger: how fast each jaw closes or opens
    kp: float = 20000.0  # N/m, stiffness of each finger's position servo
    kd: float = 40.0  # N·s/m, damping of each finger's position servo
    initial_opening: float = 0.06  # m, distance between the pads at t = 0 (0 … the stroke)


@dataclass
class BeltConfig:
    """A conveyor: a slab (its top surface is the belt) that translates along ``direction`` at
    ``speed``.  At t = 0 the slab's top-surface centre is at ``center``; over a run it moves
    speed · duration, so ``length`` must cover the parts' travel."""

    name: str = "belt"  # model-instance name of the belt
    center: List[float] = field(default_factory=lambda: [0.3, 0.0, 0.1])  # m, top-surface centre at t = 0
    # 1, horizontal unit vector of travel
    direction: List[float] = field(default_factory=lambda: [0.0, 1.0, 0.0])
    speed: float = 0.1  # m/s, along ``direction``
    length: float = 1.2  # m, along ``direction``
    width: float = 0.08  # m, across the belt
    thickness: float = 0.02  # m, of the slab
    friction: float = 0.8  # 1, Coulomb friction of the belt surface
    mass: float = 2.0  # kg, of the slab (it is speed-servoed, so it hardly matters)


@dataclass
class PartConfig:
    """A free rigid part, initially resting on its belt (centre above the belt surface by half
    its height) and turned by ``yaw_deg`` about the vertical."""

    name: str = "part"  # body and model-instance name
    belt: str = "belt"  # the belt it rests on at t = 0 (a BeltConfig.name)
    shape: str = "box"  # "box" or "cylinder" (axis vertical)
    # m, box [x, y, z] (x: across the fingers when grasped) or cylinder [diameter, height]
    size: List[float] = field(default_factory=lambda: [0.03, 0.03, 0.03])
    offset: float = 0.0  # m, along the belt from its centre at t = 0 (negative: upstream)
    yaw_deg: float = 0.0  # deg, rotation about the vertical at t = 0
    mass: float = 0.1  # kg
    friction: float = 0.8  # 1, Coulomb friction coefficient of its surface (static = dynamic)


@dataclass
class SlotConfig:
    """A place pose on the tray: where a part's centre should come to rest."""

    offset: List[float] = field(default_factory=lambda: [0.0, 0.0])  # m, [x, y] from the tray centre
    yaw_deg: float = 0.0  # deg, the part's wanted yaw relative to the tray


@dataclass
class TrayConfig:
    """A plate welded to the world; its slots are poses on its top surface."""

    center: List[float] = field(default_factory=lambda: [0.0, 0.3, 0.1])  # m, top-surface centre
    yaw_deg: float = 0.0  # deg, about the vertical
    size: List[float] = field(default_factory=lambda: [0.2, 0.12, 0.01])  # m, [x, y, thickness]
    friction: float = 0.8  # 1, Coulomb friction of its surface
    slots: List[SlotConfig] = field(default_factory=list)


@dataclass
class PickWorldConfig:
    """Everything physical in a pick-and-place station besides the arm's own model file."""

    model: str = "rvm1_5dof"  # the arm: a bundled model name or a URDF/SDFormat path
    end_effector: str = "tool"  # the arm frame the gripper's fingertip centre is welded to
    initial_q_deg: List[float] = field(default_factory=lambda: [22.5, 45.0, 30.0, 15.0, 0.0])  # deg
    time_step: float = 0.001  # s, of the discrete plant
    # Drake's discrete contact approximation: "sap", "lagged" or "similar" (those of both
    # Drake 1.51 and 1.58; scripts/contact_bench.py measures them; "tamsi" only on Drake < 1.55)
    contact_approximation: str = "sap"
    # Drake's contact model: "point", "hydroelastic" or "hydroelastic_with_fallback"
    contact_model: str = "point"
    gripper: GripperConfig = field(default_factory=GripperConfig)
    belts: List[BeltConfig] = field(default_factory=list)
    parts: List[PartConfig] = field(default_factory=list)
    tray: TrayConfig = field(default_factory=TrayConfig)


CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")
DEFAULT_APPROXIMATION = "sap"  # measured by scripts/contact_bench.py: the most accurate, and fast
SHAPE_SIZES = {"box": 3, "cylinder": 2}


def contact_approximations() -> list:
    """The discrete contact approximations of the installed Drake ("tamsi" only before 1.55)."""
    from pydrake.multibody.plant import DiscreteContactApproximation  # noqa: PLC0415

    return sorted(n[1:].lower() for n in dir(DiscreteContactApproximation) if n.startswith("k"))


def grasp_width(part: PartConfig) -> float:
    """The part's extent along its own x axis (m): what the fingers close across."""
    return float(part.size[0])


def _check_part(k: int, part: PartConfig, belts: dict) -> None:
    where = f"pick.parts[{k}]"
    if part.shape not in SHAPE_SIZES:
        raise ScenarioError(f"{where}.shape: {part.shape!r} is not one of box, cylinder")
    if len(part.size) != SHAPE_SIZES[part.shape] or min(part.size) <= 0.0:
        raise ScenarioError(f"{where}.size: a {part.shape} needs {SHAPE_SIZES[part.shape]} positive sizes "
                            f"(m)")
    if not part.mass > 0.0 or not part.friction > 0.0:
        raise ScenarioError(f"{where}.{'mass' if not part.mass > 0.0 else 'friction'}: must be positive")
    if part.belt not in belts:
        raise ScenarioError(f"{where}.belt: no belt named {part.belt!r}")
    if abs(part.offset) > belts[part.belt].length / 2:
        raise ScenarioError(f"{where}.offset: {part.offset} m starts the part off its belt "
                            f"(length {belts[part.belt].length} m)")


def _check_belt(k: int, belt: BeltConfig) -> None:
    where = f"pick.belts[{k}]"
    if len(belt.center) != 3 or len(belt.direction) != 3:
        raise ScenarioError(f"{where}.{'center' if len(belt.center) != 3 else 'direction'}: needs 3 values")
    d = np.asarray(belt.direction, dtype=float)
    if abs(d[2]) > 1e-9 or abs(np.linalg.norm(d) - 1.0) > 1e-6:
        raise ScenarioError(f"{where}.direction: must be a horizontal unit vector, got {belt.direction}")
    if min(belt.length, belt.width, belt.thickness, belt.mass, belt.friction) <= 0.0:
        raise ScenarioError(f"{where}: length, width, thickness, mass and friction must be positive")


def check_pick_world(config: PickWorldConfig) -> None:
    """ScenarioError naming the first bad field of ``config`` (the checks that need no plant)."""
    check_plant_settings(config.time_step, config.contact_approximation, config.contact_model)
    check_pick_parts(config)


PLANT_FIELDS = ("pick.time_step", "pick.contact_approximation", "pick.contact_model")
SCENARIO_PLANT_FIELDS = ("multibody.time_step", "multibody.discrete_contact_approximation",
                         "multibody.contact_model")


def check_plant_settings(time_step: float, approximation: str, model: str, names=PLANT_FIELDS) -> None:
    """ScenarioError unless the pick world's plant is discrete with a contact approximation and a
    contact model of the installed Drake; ``names``: the fields to name (``PLANT_FIELDS`` of a
    ``PickWorldConfig``, ``SCENARIO_PLANT_FIELDS`` of a scenario's ``multibody`` block)."""
    if not time_step > 0.0:
        raise ScenarioError(f"{names[0]}: a pick world's plant is discrete: must be positive, "
                            f"got {time_step}")
    if approximation not in contact_approximations():
        raise ScenarioError(f"{names[1]}: {approximation!r} is not one of "
                            f"{', '.join(contact_approximations())}")
    if model not in CONTACT_MODELS:
        raise ScenarioError(f"{names[2]}: {model!r} is not one of {', '.join(CONTACT_MODELS)}")


def check_pick_parts(config) -> None:
    """ScenarioError naming the first bad field of the gripper, belts, parts and tray of ``config``
    (a ``PickWorldConfig`` or the scenario's ``pick`` block)."""
    g = config.gripper
    if min(g.max_force, g.speed, g.kp) <= 0.0 or g.kd < 0.0:
        raise ScenarioError("pick.gripper: max_force, speed and kp must be positive, kd non-negative")
    for k, belt in enumerate(config.belts):
        _check_belt(k, belt)
    belts = {b.name: b for b in config.belts}
    if len(belts) != len(config.belts):
        raise ScenarioError("pick.belts: belt names must be unique")
    for k, part in enumerate(config.parts):
        _check_part(k, part, belts)
    if len(config.tray.center) != 3 or len(config.tray.size) != 3:
        raise ScenarioError("pick.tray: center and size need 3 values")
