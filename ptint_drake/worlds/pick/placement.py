"""Random part placement on the belts (issue 34): where each part really starts, drawn from the
scenario's seed, which only the simulated world is told.

A part of ``pick.parts`` may give ``yaw_deg: random`` (uniform in [−180°, 180°)), ``lateral:
[min, max]`` (uniform across its belt, m) and ``offset_jitter`` (± uniform, m, added to its
``offset``).  ``placed_parts`` draws them — numpy's ``default_rng`` seeded with
``measurement.seed``, in the parts' order, yaw then lateral then offset for each part — and
returns the parts as the station builds them (plain numbers).  The plan (``tasks.pick_plan``),
the targets and the controller never read these draws: they see the parts through the camera
(``worlds.pick.camera``).  ``nominal_pose`` is what the configuration alone says of a part (the
range's middle, no jitter, yaw 0 when random): where a pick aims before its part is seen.

Without a camera nothing could find such a part: ``check_placement`` rejects it (one line).
``bridging_warnings`` warns before the run when a part's placement lets it reach onto another
belt (it would ride both: dragged, turned and tilted by the one it was not put on).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.part_shape import part_height
from ptint_drake.config.pick import PartConfig

RANDOM = "random"


def is_random(part: PartConfig) -> bool:
    """Whether any of the part's placement is drawn (yaw, lateral range or offset jitter)."""
    return isinstance(part.yaw_deg, str) or isinstance(part.lateral, list) or part.offset_jitter != 0.0


def nominal_lateral(part: PartConfig) -> float:
    """m: the scalar ``lateral`` or the middle of its range."""
    if isinstance(part.lateral, list):
        return 0.5 * (part.lateral[0] + part.lateral[1])
    return float(part.lateral)


def nominal_yaw_deg(part: PartConfig) -> float:
    """deg: the configured yaw, 0 for ``random``."""
    return 0.0 if isinstance(part.yaw_deg, str) else float(part.yaw_deg)


def check_placement(pick, measurement) -> None:
    """ScenarioError naming the first bad placement field; random placement needs an rgbd sensor."""
    for k, part in enumerate(pick.parts):
        where = f"pick.parts[{k}]"
        if isinstance(part.yaw_deg, str) and part.yaw_deg != RANDOM:
            raise ScenarioError(f"{where}.yaw_deg: a number (deg) or random, got {part.yaw_deg!r}")
        if isinstance(part.lateral, list):
            if len(part.lateral) != 2 or not part.lateral[0] <= part.lateral[1]:
                raise ScenarioError(f"{where}.lateral: a number or [min, max] (m), got {part.lateral}")
        if not (math.isfinite(part.offset_jitter) and part.offset_jitter >= 0.0):
            raise ScenarioError(f"{where}.offset_jitter: must be >= 0 (m), got {part.offset_jitter}")
        if is_random(part) and (measurement is None or measurement.sensor != "rgbd"):
            field = ("yaw_deg" if isinstance(part.yaw_deg, str) else
                     "lateral" if isinstance(part.lateral, list) else "offset_jitter")
            raise ScenarioError(f"{where}.{field}: a randomly placed part needs a sensor to be found "
                                f"(measurement: {{sensor: rgbd, camera: ...}}); the plan is not told "
                                f"where it is")


def placed_parts(parts: list, seed: int) -> list[PartConfig]:
    """The parts as they start in the simulated world (module docstring); unchanged (the same
    objects) when none is placed at random."""
    if not any(is_random(p) for p in parts):
        return parts
    rng = np.random.default_rng(seed)
    out = []
    for part in parts:
        yaw = float(rng.uniform(-180.0, 180.0)) if isinstance(part.yaw_deg, str) else float(part.yaw_deg)
        lateral = (float(rng.uniform(part.lateral[0], part.lateral[1])) if isinstance(part.lateral, list)
                   else float(part.lateral))
        offset = part.offset + (float(rng.uniform(-part.offset_jitter, part.offset_jitter))
                                if part.offset_jitter else 0.0)
        out.append(dataclasses.replace(part, yaw_deg=yaw, lateral=lateral, offset=offset, offset_jitter=0.0))
    return out


def nominal_parts(parts: list) -> list[PartConfig]:
    """The parts as the configuration alone places them (``nominal_pose``)."""
    return [dataclasses.replace(p, yaw_deg=nominal_yaw_deg(p), lateral=nominal_lateral(p), offset_jitter=0.0)
            for p in parts]


def _across_reach(part: PartConfig, v: np.ndarray) -> float:
    """m: how far the part's footprint reaches from its centre along the horizontal unit ``v``
    (any yaw when random: a box's half diagonal; a cylinder's radius)."""
    if part.shape != "box":
        return 0.5 * float(part.size[0])
    if isinstance(part.yaw_deg, str):
        return 0.5 * math.hypot(float(part.size[0]), float(part.size[1]))
    yaw = math.radians(float(part.yaw_deg))
    x, y = np.array([math.cos(yaw), math.sin(yaw)]), np.array([-math.sin(yaw), math.cos(yaw)])
    return 0.5 * (float(part.size[0]) * abs(x @ v[:2]) + float(part.size[1]) * abs(y @ v[:2]))


def bridging_warnings(pick) -> list[str]:
    """One line per part whose placement (its lateral range, its yaw — any when random) lets its
    footprint reach over a parallel neighbouring belt at its own belt's height (within the part's
    height): it would rest on two belts.  Belts at an angle to the part's are not checked."""
    belts = {b.name: b for b in pick.belts}
    out = []
    for k, part in enumerate(pick.parts):
        own = belts.get(part.belt)
        if own is None:
            continue
        u = np.asarray(own.direction, float)
        v = np.array([-u[1], u[0], 0.0])  # left of the travel (``lateral`` +)
        lateral = part.lateral if isinstance(part.lateral, list) else [part.lateral, part.lateral]
        reach = _across_reach(part, v)
        low, high = float(lateral[0]) - reach, float(lateral[1]) + reach
        height = part_height(part.shape, part.size)
        for other in pick.belts:
            d = np.asarray(other.direction, float)
            if other.name == own.name or abs(abs(d @ u) - 1.0) > 1e-6:
                continue
            offset = np.asarray(other.center, float) - np.asarray(own.center, float)
            if abs(offset[2]) >= height:
                continue
            centre = float(offset @ v)
            near, far = centre - 0.5 * other.width, centre + 0.5 * other.width
            if high > near and low < far:
                edge = near if centre > 0 else far
                out.append(f"pick.parts[{k}] ({part.name}): placed {_mm(lateral)} across {own.name}, it "
                           f"reaches {1000 * (high if centre > 0 else -low):.1f} mm to that side and onto "
                           f"{other.name} (its edge {1000 * abs(edge):.1f} mm from {own.name}'s centre "
                           f"line): it would ride both belts")
    return out


def _mm(lateral: list) -> str:
    a, b = (1000 * float(v) for v in lateral)
    return f"{a:g} mm" if a == b else f"{a:g}…{b:g} mm"
