"""Mixed parts classified against the scenario's catalog by their measured top face and height
(issue 44: ``catalog_fit``), on synthetic clouds sampled on the parts' top faces."""

import math

import numpy as np
import pytest

from ptint_drake.systems.perception.catalog_fit import fit_catalog
from ptint_drake.systems.perception.part_fit import BeltRegion

SPACING = 0.0015  # m, the voxel grid's point spacing
BELT = BeltRegion(np.array([0.3, 0.0, 0.1]), np.array([0.0, 1.0, 0.0]), 0.6, 0.1)
CATALOG = [("box", [0.03, 0.03, 0.03]), ("cylinder", [0.04, 0.05]), ("box", [0.04, 0.03, 0.02])]


def top_face(kind: int, centre_xy, yaw: float, rng) -> np.ndarray:
    """Points every SPACING on the top face of catalog part ``kind`` resting on BELT (z noise 0.3 mm)."""
    shape, size = CATALOG[kind]
    half = 0.5 * (size[0] if shape == "cylinder" else max(size[0], size[1]))
    g = np.arange(-half, half + 1e-9, SPACING)
    u, v = (a.ravel() for a in np.meshgrid(g, g))
    inside = (np.hypot(u, v) <= half) if shape == "cylinder" else (np.abs(u) <= 0.5 * size[0]) & (
        np.abs(v) <= 0.5 * size[1])
    u, v = u[inside], v[inside]
    c, s = math.cos(yaw), math.sin(yaw)
    height = size[2] if shape == "box" else size[1]
    z = BELT.center[2] + height + rng.normal(0.0, 0.0003, len(u))
    return np.column_stack([centre_xy[0] + c * u - s * v, centre_xy[1] + s * u + c * v, z])


@pytest.mark.parametrize("yaw_deg", [0.0, 33.0])
def test_a_cube_a_can_and_a_flat_box_on_one_belt_are_told_apart(yaw_deg):
    rng = np.random.default_rng(1)
    where = {0: (0.3, -0.1), 1: (0.3, 0.0), 2: (0.3, 0.1)}
    cloud = np.concatenate([top_face(k, xy, math.radians(yaw_deg), rng) for k, xy in where.items()])
    fits = [f for f in fit_catalog(cloud, [BELT], CATALOG, spacing=SPACING) if f.ok]
    assert sorted(f.kind for f in fits) == [0, 1, 2]
    for f in fits:
        shape, size = CATALOG[f.kind]
        height = size[2] if shape == "box" else size[1]
        assert np.linalg.norm(f.position[0:2] - where[f.kind]) < 1e-3
        assert f.position[2] == pytest.approx(BELT.center[2] + 0.5 * height, abs=1e-3)
    can = next(f for f in fits if f.kind == 1)
    assert can.symmetry == 0.0 and can.yaw == 0.0


def test_a_part_of_no_declared_kind_is_not_fitted():
    rng = np.random.default_rng(2)
    # a 30 mm square top 40 mm above the belt: the cube's top face at another height
    cloud = top_face(0, (0.3, 0.0), 0.0, rng) + [0.0, 0.0, 0.01]
    fits = fit_catalog(cloud, [BELT], CATALOG, spacing=SPACING)
    assert fits and not any(f.ok for f in fits)
    assert "height" in fits[0].reason


def test_two_touching_cubes_are_split_into_two_cubes():
    rng = np.random.default_rng(3)
    cloud = np.concatenate([top_face(0, (0.3, -0.015), 0.0, rng), top_face(0, (0.3, 0.0151), 0.0, rng)])
    fits = [f for f in fit_catalog(cloud, [BELT], CATALOG, spacing=SPACING) if f.ok]
    assert [f.kind for f in fits] == [0, 0]
    assert sorted(f.position[1] for f in fits) == pytest.approx([-0.015, 0.0151], abs=1.5e-3)
