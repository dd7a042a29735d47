"""One-line checks of single fields, shared by the validation of every block (each raises a
``ScenarioError`` whose message names the field)."""

import math

from ptint_drake.config.errors import ScenarioError


def vector3(value, where: str) -> None:
    """3 finite numbers."""
    if len(value) != 3:
        raise ScenarioError(f"{where}: must have 3 entries, got {len(value)}")
    if not all(math.isfinite(v) for v in value):
        raise ScenarioError(f"{where}: must be finite, got {list(value)}")


def nonnegative(value: float, where: str) -> None:
    """A finite number >= 0."""
    if not (math.isfinite(value) and value >= 0.0):
        raise ScenarioError(f"{where}: must be >= 0, got {value}")


def positive(value: float, where: str) -> None:
    """A finite number > 0."""
    if not (math.isfinite(value) and value > 0.0):
        raise ScenarioError(f"{where}: must be > 0, got {value}")
