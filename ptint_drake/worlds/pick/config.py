"""Typed settings of the pick-and-place world, loadable with Drake's ``yaml_load_typed``
(the style of ``scenario``: plain dataclasses, lists of floats, every field's unit beside it).

World frame: the arm's base frame (z up).  A *belt* is a conveyor whose top surface is a slab
riding a prismatic joint (``scene``); a *part* is a free box or cylinder resting on a belt; the
*tray* is a welded plate whose *slots* are place poses.  ``PickWorldConfig`` gathers them with
the plant's settings (Drake's ``MultibodyPlantConfig`` fields that matter here).
(No ``from __future__ import annotations`` here: ``yaml_load_typed`` reads the field types.)
"""



import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.part_shape import TIP_CLEARANCE, check_part_shape, part_height
from ptint_drake.config.pick import (  # noqa: F401
    BeltConfig,
    BinConfig,
    GripperConfig,
    PartConfig,
    PickWorldConfig,
    SlotConfig,
    TrayConfig,
)
from ptint_drake.systems.hand.datasheets import check_gripper

CONTACT_MODELS = ("point", "hydroelastic", "hydroelastic_with_fallback")
DEFAULT_APPROXIMATION = "sap"  # measured by scripts/contact_bench.py: the most accurate, and fast


def contact_approximations() -> list:
    """The discrete contact approximations of the installed Drake ("tamsi" only before 1.55)."""
    from pydrake.multibody.plant import DiscreteContactApproximation  # noqa: PLC0415

    return sorted(n[1:].lower() for n in dir(DiscreteContactApproximation) if n.startswith("k"))


def grasp_width(part: PartConfig) -> float:
    """The part's extent along its own x axis (m): what the fingers close across."""
    return float(part.size[0])


def grip_height(part: PartConfig, reach: float) -> float:
    """How far above the part's centre the fingertip centre grips it (m): 0 where the fingers,
    reaching ``reach`` m past the fingertip centre, keep ``config.part_shape.TIP_CLEARANCE`` above
    the part's base; higher on a part too short for that — gripped at its centre, a 20 mm part
    would have the fingertips of the bundled grippers on its belt and, at the place, on the tray."""
    return max(0.0, reach + TIP_CLEARANCE - part_height(part.shape, part.size) / 2)


def _check_part(k: int, part: PartConfig, belts: dict) -> None:
    where = f"pick.parts[{k}]"
    check_part_shape(where, part.shape, part.size, part.mass, part.friction)
    if part.belt not in belts:
        raise ScenarioError(f"{where}.belt: no belt named {part.belt!r}")
    if abs(part.offset) + abs(part.offset_jitter) > belts[part.belt].length / 2:
        raise ScenarioError(f"{where}.offset: {part.offset} m starts the part off its belt "
                            f"(length {belts[part.belt].length} m)")
    lateral = part.lateral if isinstance(part.lateral, list) else [part.lateral]
    if max(abs(v) for v in lateral) > belts[part.belt].width / 2:
        raise ScenarioError(f"{where}.lateral: {part.lateral} m puts the part's centre off its belt "
                            f"(width {belts[part.belt].width} m)")


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
    check_gripper(g)  # a bundled datasheet gripper's force and speed ranges
    for k, belt in enumerate(config.belts):
        _check_belt(k, belt)
    belts = {b.name: b for b in config.belts}
    if len(belts) != len(config.belts):
        raise ScenarioError("pick.belts: belt names must be unique")
    for k, part in enumerate(config.parts):
        _check_part(k, part, belts)
    if len(config.tray.center) != 3 or len(config.tray.size) != 3:
        raise ScenarioError("pick.tray: center and size need 3 values")
    for k, box in enumerate(config.bins):
        _check_bin(k, box)
    taken = {b.name for b in config.belts} | {p.name for p in config.parts} | {"tray", "floor"}
    for k, box in enumerate(config.bins):
        if box.name in taken:
            raise ScenarioError(f"pick.bins[{k}].name: {box.name!r} is taken (by a belt, a part, the tray, "
                                f"the floor or another bin)")
        taken.add(box.name)


def _check_bin(k: int, box: BinConfig) -> None:
    where = f"pick.bins[{k}]"
    for name in ("center", "size"):
        if len(getattr(box, name)) != 3:
            raise ScenarioError(f"{where}.{name}: needs 3 values (m)")
    if min(box.size) <= 0.0:
        raise ScenarioError(f"{where}.size: [x, y, depth] must be positive, got {box.size}")
    for name in ("wall", "friction"):
        if not getattr(box, name) > 0.0:
            raise ScenarioError(f"{where}.{name}: must be positive, got {getattr(box, name)}")
