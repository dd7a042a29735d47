"""A part's solid as a scenario declares it: its shape, sizes, mass and friction, and the one
check of them that a declared part (``pick.parts``) and a catalog kind (``pick.line.catalog``)
both get."""

from __future__ import annotations

from ptint_drake.config.errors import ScenarioError

SHAPE_SIZES = {"box": 3, "cylinder": 2}  # sizes per shape: box [x, y, z]; cylinder [diameter, height]


def check_part_shape(where: str, shape: str, size: list, mass: float, friction: float) -> None:
    """One line naming ``where``'s field: an unknown shape, the wrong number of sizes or a size
    that is not positive, a mass or friction that is not positive."""
    if shape not in SHAPE_SIZES:
        raise ScenarioError(f"{where}.shape: {shape!r} is not one of box, cylinder")
    if len(size) != SHAPE_SIZES[shape] or min(size) <= 0.0:
        raise ScenarioError(f"{where}.size: a {shape} needs {SHAPE_SIZES[shape]} positive sizes (m)")
    if not mass > 0.0 or not friction > 0.0:
        raise ScenarioError(f"{where}.{'mass' if not mass > 0.0 else 'friction'}: must be positive")
