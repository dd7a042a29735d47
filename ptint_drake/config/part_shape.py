"""A part's solid as a scenario declares it: its shape, sizes, mass and friction, and the one
check of them that a declared part (``pick.parts``) and a catalog kind (``pick.line.catalog``)
both get."""

from __future__ import annotations

import numpy as np

from ptint_drake.config.errors import ScenarioError

SHAPE_SIZES = {"box": 3, "cylinder": 2}  # sizes per shape: box [x, y, z]; cylinder [diameter, height]
# m: the least height of the fingertips above what a part stands on (a belt, the tray) while the
# fingers hold it (``worlds.pick.config.grip_height``).  The bundled parts (30 mm tall) and
# grippers (fingers reaching 10 mm past the fingertip centre) have exactly this much when gripped
# at the centre.
TIP_CLEARANCE = 0.005
MIN_HELD = 0.005  # m: the least height of a part the pads hold above the fingertips


def part_height(shape: str, size: list) -> float:
    """A part's height standing on its base (m): a box's z size, a cylinder's length."""
    return float(size[2] if shape == "box" else size[1])


def footprint_radius(shape: str, size: list) -> float:
    """m: the radius of a part's footprint standing on its base, at any yaw: a box's half diagonal
    of its top, a cylinder's radius."""
    return 0.5 * float(np.hypot(size[0], size[1])) if shape == "box" else 0.5 * float(size[0])


def check_part_shape(where: str, shape: str, size: list, mass: float, friction: float) -> None:
    """One line naming ``where``'s field: an unknown shape, the wrong number of sizes or a size
    that is not positive, a part too short to hold (``MIN_HELD`` of it above ``TIP_CLEARANCE``),
    a mass or friction that is not positive."""
    if shape not in SHAPE_SIZES:
        raise ScenarioError(f"{where}.shape: {shape!r} is not one of box, cylinder")
    if len(size) != SHAPE_SIZES[shape] or min(size) <= 0.0:
        raise ScenarioError(f"{where}.size: a {shape} needs {SHAPE_SIZES[shape]} positive sizes (m)")
    height = part_height(shape, size)
    if height - TIP_CLEARANCE < MIN_HELD:
        raise ScenarioError(f"{where}.size: a part {1e3 * height:g} mm tall is too short to hold: with the "
                            f"fingertips {1e3 * TIP_CLEARANCE:g} mm above its base, the pads would hold less "
                            f"than {1e3 * MIN_HELD:g} mm of it")
    if not mass > 0.0 or not friction > 0.0:
        raise ScenarioError(f"{where}.{'mass' if not mass > 0.0 else 'friction'}: must be positive")
