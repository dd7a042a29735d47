"""Which belts the perception knows: the regions of ``measurement.camera.belts`` (``belt_regions``),
or one derived under each object's straight path (``belts_under_paths``), and the belt each object
rides (``perception_belts``)."""

from __future__ import annotations

import numpy as np

from ptint_drake.config.part_shape import part_height
from ptint_drake.systems.perception.part_fit import BeltRegion


def belt_regions(configs) -> list[BeltRegion]:
    """``BeltRegion``s of ``measurement.camera.belts`` entries."""
    return [BeltRegion(np.asarray(b.center, float), np.asarray(b.direction, float), float(b.length),
                       float(b.width)) for b in configs]


# m, a derived belt's extra width beside its part's footprint (each side; narrow, so that the belts
# of two objects on parallel paths do not take each other's parts) and length (each end)
BELT_MARGIN = 0.005
BELT_END_MARGIN = 0.03


def belts_under_paths(targets, duration: float, shape: str, size) -> tuple[list[BeltRegion], list[int]]:
    """A belt under each object's straight horizontal path over [0, duration] (the conveyor the
    scenario's ``linear`` target describes: its top surface half the part's height below the
    centre), and the belt of each object; ``ValueError`` naming the object otherwise."""
    belts, of = [], []
    half = 0.5 * part_height(shape, size)
    for i, target in enumerate(targets):
        target = getattr(target, "position", target)  # an oriented target: its motion
        start, velocity = getattr(target, "start", None), getattr(target, "velocity", None)
        if start is None or velocity is None or getattr(target, "compiled", None) is None:
            raise ValueError(f"interceptions[{i}].target: an rgbd camera sees parts on conveyors: "
                             "the target must be linear")
        speed = float(np.linalg.norm(velocity[0:2]))
        if abs(float(velocity[2])) > 1e-12 or speed <= 0.0:
            raise ValueError(f"interceptions[{i}].target.linear.velocity: an rgbd camera sees parts on "
                             f"conveyors: the motion must be horizontal and non-zero, got {list(velocity)}")
        end = start + velocity * duration
        centre = 0.5 * (start + end) - [0.0, 0.0, half]
        diagonal = float(np.hypot(*np.asarray(size, float)[:2])) if shape == "box" else float(size[0])
        belts.append(BeltRegion(centre, velocity / np.linalg.norm(velocity), speed * duration + diagonal
                                + 2 * BELT_END_MARGIN, diagonal + 2 * BELT_MARGIN))
        of.append(i)
    return belts, of


def perception_belts(measurement, targets, duration: float) -> tuple[list[BeltRegion], list[int]]:
    """The belts the perception knows (``measurement.camera.belts``, or one under each object's
    path: ``belts_under_paths``) and the belt of each object (configured belts: the one whose
    centre line passes nearest the object's start, below it)."""
    c = measurement.camera
    if not c.belts:
        return belts_under_paths(targets, duration, c.part_shape, c.part_size)
    belts = belt_regions(c.belts)
    of = []
    for target in targets:
        start = np.asarray(target.evaluate(0.0), float)[0:3]
        distances = []
        for b in belts:
            u, v = b.frame()
            d = start - b.center
            distances.append(abs(d @ v) + max(abs(d @ u) - 0.5 * b.length, 0.0) + abs(d[2]))
        of.append(int(np.argmin(distances)))
    return belts, of
