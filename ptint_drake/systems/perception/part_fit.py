"""Part poses fitted to a point cloud in the world frame, from configured geometry only.

``fit_parts(points, belts, shape, size)`` does, over the configured belts (``BeltRegion``: a
horizontal rectangle, the conveyor's top surface):

1. background removal: keep the points above a belt's rectangle widened by the part's
   half-diagonal (of its top face) along and across — a part whose centre is on its belt may
   overhang the belt's ends and edges by that much, and its top face must stay whole — whose
   height over that belt's plane is in (``BELT_BAND``, part height + ``TOP_BAND``]: the belt
   itself, anything beside it and anything well above a part are dropped;
2. clustering, over all belts' points at once (a point in two belts' bands is one point):
   points closer than ``CLUSTER_RADIUS`` are connected (scipy ``cKDTree`` pairs,
   ``connected_components``); a cluster whose top face is k ≥ 2 parts' area (parts touching) is
   split by k-means on its top-face points (scipy ``kmeans2``, fixed seed); each part is then
   on the belt whose centre line passes nearest its fitted centre (the belt under its centre:
   a part overhanging into a neighbour belt's band is fitted once, on its own belt);
3. the fit to the known shape, from the top face (points within ``TOP_BAND`` of the highest):
   a box — the minimum-area rectangle around the top face's convex hull (scipy ``ConvexHull``;
   rotating calipers over its edges) gives the centre (x, y) and the yaw, folded by the box's
   symmetry (90° for a square top, 180° otherwise; the sides matched to ``size``); a cylinder —
   the top face's plane normal (SVD) is the axis and a least-squares circle (Kåsa's algebraic
   fit) through the hull gives the centre; yaw is meaningless (any). The centre's height is
   the top face's mean height minus half the part's height.

Quality per fit: ``inliers`` (top-face points), ``residual`` (m: RMS distance of the top face
to its plane, and the largest difference between the fitted and the known top-face sides or
diameter), and a covariance (diagonal: the pixel footprint's quantisation over the top-face
edge for x, y; the plane scatter over √n for z).  A fit is ``ok`` when its top face has at
least ``min_points`` points and ``COMPLETE`` of those a whole top face has at the cloud's point
spacing, its sides match the known ones within ``SIZE_TOLERANCE`` and its
plane is flat within ``PLANE_TOLERANCE``: an occluded part (a cut top face), the arm in the
belt's height band or two parts that cannot be separated fail and are dropouts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.cluster.vq import kmeans2
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError, cKDTree

from ptint_drake.config.part_shape import part_height

BELT_BAND = 0.004  # m, points this close to the belt plane are the belt (≈ 10 σ of the depth noise at 0.5 m)
TOP_BAND = 0.004  # m, the top face: points within this of the cluster's highest
CLUSTER_RADIUS = 0.006  # m, neighbours closer than this are one cluster (a few pixel footprints)
SIZE_TOLERANCE = 0.0025  # m, fitted vs known top-face side (or diameter)
COMPLETE = 0.85  # a top face with fewer points than this share of the expected count is cut
PLANE_BAND = 0.0015  # m, the top face's plane is fitted to the points this close to its median height
PLANE_TOLERANCE = 0.002  # m, RMS of the top face about its plane
MIN_POINTS = 30  # top-face points (after the voxel grid) for a fit to count


@dataclass
class BeltRegion:
    """A conveyor's top surface: centre (m), horizontal unit direction, length and width (m)."""

    center: np.ndarray
    direction: np.ndarray
    length: float
    width: float

    def frame(self) -> tuple[np.ndarray, np.ndarray]:
        """(u along, v across) horizontal unit vectors of the belt."""
        u = np.array([self.direction[0], self.direction[1], 0.0])
        u /= np.linalg.norm(u)
        return u, np.array([-u[1], u[0], 0.0])


@dataclass
class PartFit:
    """One part seen on belt ``belt``: its centre (m, world), yaw (rad, folded into
    [−symmetry/2, symmetry/2); 0 for a cylinder), ``symmetry`` (rad: π/2 for a square top, π
    for a rectangle, 0 for any yaw), quality and a 3×3 position covariance (m²)."""

    belt: int
    position: np.ndarray
    yaw: float
    symmetry: float
    inliers: int
    residual: float
    covariance: np.ndarray
    ok: bool
    reason: str = ""
    axis: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, 1.0]))
    kind: int = 0  # the catalog class it was fitted as (``catalog_fit``; one known shape: 0)

    def rotation(self) -> np.ndarray:
        """R_WP: yaw about the fitted axis (vertical parts: about world z)."""
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _top_sides(shape: str, size) -> tuple[float, float]:
    return (float(size[0]), float(size[1])) if shape == "box" else (float(size[0]), float(size[0]))


def reach(shape: str, size) -> float:
    """m: half the diagonal of the part's top face (of the square around a cylinder's): how far a
    part whose centre is on a belt may overhang its edges."""
    return 0.5 * math.hypot(*_top_sides(shape, size))


def in_band(points: np.ndarray, belt: BeltRegion, shape: str, size) -> np.ndarray:
    """Per point (N×3): above ``belt``'s rectangle widened by ``reach`` and in its part band (step 1)."""
    u, v = belt.frame()
    d = points - belt.center
    along, across, up = d @ u, d @ v, d[:, 2]
    r = reach(shape, size)
    return ((np.abs(along) <= 0.5 * belt.length + r) & (np.abs(across) <= 0.5 * belt.width + r)
            & (up > BELT_BAND) & (up <= part_height(shape, size) + TOP_BAND))


def belt_points(points: np.ndarray, belts: list[BeltRegion], shape: str, size) -> np.ndarray:
    """The points (N×3) in any of ``belts``' part bands (step 1), each once."""
    keep = np.zeros(len(points), dtype=bool)
    for belt in belts:
        keep |= in_band(points, belt, shape, size)
    return points[keep]


def nearest_belt(xy: np.ndarray, belts: list[BeltRegion]) -> int:
    """The belt whose centre line (a segment: the belt's length) passes nearest the point ``xy``."""
    distances = []
    for belt in belts:
        u, v = belt.frame()
        d = np.array([xy[0] - belt.center[0], xy[1] - belt.center[1], 0.0])
        distances.append(math.hypot(d @ v, max(abs(d @ u) - 0.5 * belt.length, 0.0)))
    return int(np.argmin(distances))


def clusters(points: np.ndarray) -> list[np.ndarray]:
    """Connected groups of points (step 2, before splitting), largest first."""
    if len(points) == 0:
        return []
    pairs = cKDTree(points).query_pairs(CLUSTER_RADIUS, output_type="ndarray")
    n = len(points)
    graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    count, labels = connected_components(graph, directed=False)
    order = np.argsort(labels, kind="stable")  # (each group's points in their order)
    groups = np.split(points[order], np.cumsum(np.bincount(labels, minlength=count))[:-1])
    return sorted(groups, key=len, reverse=True)


def _top_face(points: np.ndarray) -> np.ndarray:
    return points[points[:, 2] >= points[:, 2].max() - TOP_BAND]


def _hull(xy: np.ndarray) -> np.ndarray | None:
    try:
        return xy[ConvexHull(xy).vertices]
    except (QhullError, ValueError):
        return None


def min_area_rectangle(xy: np.ndarray) -> tuple[np.ndarray, float, float, float] | None:
    """(centre, yaw of side a, side a, side b) of the smallest rectangle around ``xy``
    (rotating calipers: one side lies on a convex-hull edge; all edges at once)."""
    hull = _hull(xy)
    if hull is None:
        return None
    edges = np.roll(hull, -1, axis=0) - hull
    edges = edges[np.any(edges != 0.0, axis=1)]
    if len(edges) == 0:
        return None
    angles = np.arctan2(edges[:, 1], edges[:, 0])
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    a = c * hull[:, 0] + s * hull[:, 1]  # per edge (rows), the hull's coordinates along (a, b)
    b = c * hull[:, 1] - s * hull[:, 0]
    lo_a, hi_a, lo_b, hi_b = a.min(axis=1), a.max(axis=1), b.min(axis=1), b.max(axis=1)
    k = int(np.argmin((hi_a - lo_a) * (hi_b - lo_b)))  # (the first of equal areas)
    mid_a, mid_b = 0.5 * (lo_a[k] + hi_a[k]), 0.5 * (lo_b[k] + hi_b[k])
    ck, sk = float(c[k, 0]), float(s[k, 0])
    centre = np.array([ck * mid_a - sk * mid_b, sk * mid_a + ck * mid_b])
    return centre, float(angles[k]), float(hi_a[k] - lo_a[k]), float(hi_b[k] - lo_b[k])


def _circle(xy: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Kåsa's algebraic least-squares circle: (centre, radius)."""
    hull = _hull(xy)
    if hull is None or len(hull) < 3:
        return None
    A = np.column_stack([2.0 * hull, np.ones(len(hull))])
    b = np.sum(hull ** 2, axis=1)
    (cx, cy, c0), *_ = np.linalg.lstsq(A, b, rcond=None)
    return np.array([cx, cy]), math.sqrt(max(c0 + cx * cx + cy * cy, 0.0))


def fold_yaw(yaw: float, symmetry: float) -> float:
    """``yaw`` folded into [−symmetry/2, symmetry/2) (symmetry 0: any yaw, returns 0)."""
    if symmetry <= 0.0:
        return 0.0
    return (yaw + 0.5 * symmetry) % symmetry - 0.5 * symmetry


def yaw_symmetry(shape: str, size) -> float:
    """rad: π/2 for a square-topped box, π for another box, 0 (any) for a cylinder."""
    if shape != "box":
        return 0.0
    return 0.5 * math.pi if abs(float(size[0]) - float(size[1])) < 1e-9 else math.pi


def expected_top_points(shape: str, size, spacing: float) -> float:
    """Top-face points of a whole, unoccluded part sampled every ``spacing`` m."""
    a, b = _top_sides(shape, size)
    return (a * b if shape == "box" else math.pi * a * a / 4.0) / spacing ** 2


def fit_part(points: np.ndarray, belt_index: int, shape: str, size, *, min_points: int = MIN_POINTS,
             footprint: float = 0.001, spacing: float = 0.0) -> PartFit:
    """The part's pose from its cluster (step 3); ``footprint``: m per pixel at the part;
    ``spacing``: m between the cloud's points (the voxel grid; 0: no check of completeness)."""
    top = _top_face(points)
    n = len(top)
    nothing = PartFit(belt_index, np.full(3, np.nan), 0.0, yaw_symmetry(shape, size), n, math.inf,
                      np.full((3, 3), np.nan), False)
    if n < min_points:
        nothing.reason = f"{n} top-face points (< {min_points})"
        return nothing
    # the plane from the points near the face's median height (not the rim of the side walls)
    flat_face = top[np.abs(top[:, 2] - np.median(top[:, 2])) <= PLANE_BAND]
    flat_face = flat_face if len(flat_face) >= 3 else top
    centroid = flat_face.mean(axis=0)
    _, sv, vt = np.linalg.svd(flat_face - centroid, full_matrices=False)
    axis = vt[2] if vt[2][2] > 0.0 else -vt[2]
    flat = float(sv[2] / math.sqrt(len(flat_face)))
    xy = top[:, 0:2]
    sides = _top_sides(shape, size)
    if shape == "box":
        rect = min_area_rectangle(xy)
        if rect is None:
            nothing.reason = "degenerate top face"
            return nothing
        centre, yaw, a, b = rect
        if abs(a - sides[1]) + abs(b - sides[0]) < abs(a - sides[0]) + abs(b - sides[1]):
            yaw, a, b = yaw + 0.5 * math.pi, b, a  # side a is the part's x side
        size_error = max(abs(a - sides[0]), abs(b - sides[1]))
    else:
        circle = _circle(xy)
        if circle is None:
            nothing.reason = "degenerate top face"
            return nothing
        centre, radius = circle
        yaw, size_error = 0.0, abs(2.0 * radius - sides[0])
    symmetry = yaw_symmetry(shape, size)
    position = np.array([centre[0], centre[1], centroid[2] - 0.5 * part_height(shape, size)])
    edge_points = max(4.0 * math.sqrt(n), 1.0)
    var_xy = footprint ** 2 / 12.0 / edge_points * 4.0 + (size_error / 2.0) ** 2 / 3.0
    var_z = flat ** 2 + footprint ** 2 / 12.0 / n
    fit = PartFit(belt_index, position, fold_yaw(yaw, symmetry), symmetry, n, max(flat, size_error),
                  np.diag([var_xy, var_xy, var_z]), True, "", axis)
    expected = expected_top_points(shape, size, spacing) if spacing > 0.0 else 0.0
    if n < COMPLETE * expected:
        fit.ok, fit.reason = False, f"top face cut ({n} of ~{expected:.0f} points: occluded?)"
    elif size_error > max(SIZE_TOLERANCE, 2.0 * footprint):  # (an edge is known to ± a pixel)
        fit.ok, fit.reason = False, f"top face {1000 * size_error:.1f} mm off the known size"
    elif flat > PLANE_TOLERANCE:
        fit.ok, fit.reason = False, f"top face not flat ({1000 * flat:.1f} mm RMS)"
    return fit


def _split(cluster: np.ndarray, shape: str, size) -> list[np.ndarray]:
    """A cluster holding k touching parts split into k (k from its top face's area)."""
    top = _top_face(cluster)
    a, b = _top_sides(shape, size)
    hull = _hull(top[:, 0:2]) if len(top) >= 3 else None
    if hull is None:
        return [cluster]
    area = ConvexHull(hull).volume
    k = round(area / (a * b if shape == "box" else math.pi * a * a / 4.0))
    if k < 2:
        return [cluster]
    _, labels = kmeans2(top[:, 0:2], k, seed=np.random.default_rng(0), minit="++")
    centres = np.array([top[labels == j, 0:2].mean(axis=0) for j in range(k) if np.any(labels == j)])
    nearest = np.argmin(np.linalg.norm(cluster[:, None, 0:2] - centres[None], axis=2), axis=1)
    return [cluster[nearest == j] for j in range(len(centres))]


def fit_parts(points: np.ndarray, belts: list[BeltRegion], shape: str, size, *,
              min_points: int = MIN_POINTS, footprint: float = 0.001, spacing: float = 0.0) -> list[PartFit]:
    """Every part seen on ``belts`` (see the module docstring); failed fits included (``ok``
    False, with their ``reason``) so a caller can name why a part was not seen."""
    fits = []
    if not belts:
        return fits
    for cluster in clusters(belt_points(points, belts, shape, size)):
        if len(cluster) < min_points // 2:
            continue  # specks: noise, an edge of something
        for part in _split(cluster, shape, size):
            fit = fit_part(part, 0, shape, size, min_points=min_points, footprint=footprint, spacing=spacing)
            # the belt under its centre (a failed fit: under its top face's middle)
            fit.belt = nearest_belt(fit.position if fit.ok else _top_face(part).mean(axis=0), belts)
            fits.append(fit)
    return fits
