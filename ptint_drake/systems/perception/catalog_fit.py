"""Parts of several kinds fitted to one point cloud (issue 44): each cluster classified against a
catalog of known shapes and sizes by its measured top face and height.

``fit_catalog(points, belts, catalog)`` does what ``part_fit.fit_parts`` does for one known
shape, for a catalog (a list of (shape, size): the scenario's declared kinds of part):

1. background removal: the points in any class's part band over any belt (``part_fit.in_band``);
2. clustering (``part_fit.clusters``);
3. per cluster, the fit to each class (``part_fit.fit_part``: the top face's rectangle or
   circle against the class's sides or diameter) and the class's height against the measured
   one (the top face's height over the plane of the belt under it, within
   ``HEIGHT_TOLERANCE``); the cluster is the class whose fit is good with the smallest size,
   height and shape error (``PartFit.kind``: its index in the catalog).  The shape error tells a
   square from a circle of the same width, which the size alone does not (a disc's bounding
   rectangle is the cube's square): the top face's fill — the area of its points' convex hull
   over its smallest rectangle's (``part_fit.min_area_rectangle``), 1 for a box, π/4 for a
   cylinder, each shrunk alike by the sampling — off the class's, × the class's width (m).
   Measured on line_two_belts_rgbd's camera, a 30 mm cube at yaw 0 beside 30 mm discs: without
   it 5 of 16 frames classed the cube a disc.  A cluster no class fits is
   split as touching parts would be, with each class's top-face area giving the count
   (``part_fit._split``), and kept split when every piece fits some class; otherwise it is
   one failed fit (its best class's, with the reason).
"""

from __future__ import annotations

import math

import numpy as np

from ptint_drake.config.part_shape import part_height
from ptint_drake.systems.perception.part_fit import (MIN_POINTS, BeltRegion, PartFit, _hull, _split,
                                                     _top_face, clusters, fit_part, in_band,
                                                     min_area_rectangle, nearest_belt)

HEIGHT_TOLERANCE = 0.004  # m, measured (top face over its belt) vs the class's height
FILL = {"box": 1.0, "cylinder": math.pi / 4.0}  # a top face's area over its smallest rectangle's


def catalog_points(points: np.ndarray, belts: list[BeltRegion], catalog: list) -> np.ndarray:
    """The points (N×3) in any class's part band over any belt (step 1), each once."""
    keep = np.zeros(len(points), dtype=bool)
    for belt in belts:
        for shape, size in catalog:
            keep |= in_band(points, belt, shape, size)
    return points[keep]


def fill_ratio(points: np.ndarray) -> float:
    """The top face's convex hull area over its smallest rectangle's (module docstring; nan: none).
    One hull of the face's points; the area (shoelace) and the rectangle from its vertices."""
    xy = _top_face(points)[:, 0:2]
    hull = _hull(xy) if len(xy) >= 3 else None
    rect = min_area_rectangle(hull) if hull is not None and len(hull) >= 3 else None
    if rect is None or rect[2] * rect[3] <= 0.0:
        return math.nan
    x, y = hull[:, 0], hull[:, 1]
    area = 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))
    return area / (rect[2] * rect[3])


def classified_fit(points: np.ndarray, belts: list[BeltRegion], catalog: list, **fit) -> PartFit:
    """The cluster's best class (step 3): its fit, with ``kind``; every class failing: the failed
    fit with the smallest error (its reason names the class)."""
    best, best_cost = None, np.inf
    fill = fill_ratio(points) if len({shape for shape, _ in catalog}) > 1 else math.nan
    for kind, (shape, size) in enumerate(catalog):
        f = fit_part(points, 0, shape, size, **fit)
        f.kind = kind
        found = np.all(np.isfinite(f.position))
        f.belt = nearest_belt(f.position if found else _top_face(points).mean(axis=0), belts)
        height_error = np.inf
        if found:
            top = f.position[2] + 0.5 * part_height(shape, size)
            height_error = abs(top - float(belts[f.belt].center[2]) - part_height(shape, size))
            if f.ok and height_error > HEIGHT_TOLERANCE:
                f.ok, f.reason = False, f"{1000 * height_error:.1f} mm off a {shape}'s height"
        shape_error = abs(fill - FILL[shape]) * float(size[0]) if np.isfinite(fill) else 0.0
        cost = (0.0 if f.ok else 1.0) + min(f.residual + height_error + shape_error, 0.5)
        if cost < best_cost:
            best, best_cost = f, cost
        if not f.ok and f.reason:
            f.reason = f"as {shape} {list(size)}: {f.reason}"
    return best


def fit_catalog(points: np.ndarray, belts: list[BeltRegion], catalog: list, *, min_points: int = MIN_POINTS,
                footprint: float = 0.001, spacing: float = 0.0) -> list[PartFit]:
    """Every part seen on ``belts``, each of a class of ``catalog`` (module docstring); failed
    fits included (``ok`` False, with their ``reason``)."""
    fits = []
    if not belts:
        return fits
    options = {"min_points": min_points, "footprint": footprint, "spacing": spacing}
    for cluster in clusters(catalog_points(points, belts, catalog)):
        if len(cluster) < min_points // 2:
            continue  # specks: noise, an edge of something
        whole = classified_fit(cluster, belts, catalog, **options)
        if whole.ok:
            fits.append(whole)
            continue
        for shape, size in catalog:  # touching parts: split by this class's area, kept if all fit
            pieces = _split(cluster, shape, size)
            if len(pieces) < 2:
                continue
            split = [classified_fit(p, belts, catalog, **options) for p in pieces]
            if all(f.ok for f in split):
                fits.extend(split)
                break
        else:
            fits.append(whole)
    return fits
