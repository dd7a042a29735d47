"""Session 53: a line's place keeps the open fingers clear of the tray's parts at every yaw it
offers, the slot's own included (``grip.puts``, ``grip.tray_clearance``): a box's footprint is its
rectangle, not the disc of its half diagonal.  Found on an iiwa 14 line as a new user writes it
(40 × 30 mm boxes in slots 50 mm apart along their 40 mm side): the third box, put between two
placed ones at the slot's own yaw, pushed both 4 mm off their slots (`touched box_0, box_1`)."""

import math

import numpy as np
import pytest

from ptint_drake.config.pick import PartConfig, PickConfig, PickTaskConfig, SlotConfig, TrayConfig
from ptint_drake.worlds.pick.grasp_gate import FINGER_MARGIN
from ptint_drake.worlds.pick.line.grip import in_tray, puts, tray_clearance

BOX = PartConfig(name="box_0", shape="box", size=[0.04, 0.03, 0.03], mass=0.2)
CUBE = PartConfig(name="cube_0", shape="box", size=[0.03, 0.03, 0.03], mass=0.1)
WSG = (0.01, 0.025)  # m: a finger's thickness and width (about the WSG 50's)
MARGIN = 0.012


def _rect(centre, yaw, size):
    from ptint_drake.worlds.pick.line.grip import _rectangle
    return (np.asarray(centre[:2], float), _rectangle(centre, yaw, 0.5 * size[0], 0.5 * size[1]))


def test_aligned_the_gap_is_the_neighbour_s_face_less_the_finger_s_outer_face():
    """Fingers along x at the origin, a 40 mm box's face 30 mm out: the finger's outer face is at
    half the opening (26 mm) + 10 mm = 36 mm, so they overlap by 6 mm; at 70 mm apart the gap is
    70 − 20 − 36 = 14 mm; across (the box 60 mm away in y) the finger's 12.5 mm half width."""
    opening = BOX.size[0] + MARGIN
    assert tray_clearance(np.zeros(3), 0.0, opening, WSG, _rect((0.05, 0.0), 0.0, BOX.size)) == \
        pytest.approx(-0.006)
    assert tray_clearance(np.zeros(3), 0.0, opening, WSG, _rect((0.07, 0.0), 0.0, BOX.size)) == \
        pytest.approx(0.014)
    assert tray_clearance(np.zeros(3), 0.0, opening, WSG, _rect((0.0, 0.06), 0.0, BOX.size)) == \
        pytest.approx(0.06 - 0.015 - 0.0125)


def test_a_turned_neighbour_is_never_nearer_than_its_true_gap():
    """The edge-normal separation is a lower bound of the true gap: a box turned 30° at 70 mm is
    checked against the distance from the finger's rectangle to its nearest corner (sampled)."""
    opening = BOX.size[0] + MARGIN
    centre, corners = _rect((0.07, 0.01), math.radians(30.0), BOX.size)
    found = tray_clearance(np.zeros(3), 0.0, opening, WSG, (centre, corners))
    # the true gap, sampled: the right finger's rectangle x ∈ [0.026, 0.036], y ∈ [−0.0125, 0.0125]
    t = np.linspace(0.0, 1.0, 200)
    edges = [corners[i] + np.outer(t, corners[(i + 1) % 4] - corners[i]) for i in range(4)]
    points = np.vstack(edges)
    dx = np.maximum.reduce([0.026 - points[:, 0], points[:, 0] - 0.036, np.zeros(len(points))])
    dy = np.maximum(np.abs(points[:, 1]) - 0.0125, 0.0)
    true = float(np.min(np.hypot(dx, dy)))
    assert 0.0 < found <= true + 1e-9 and found > true - 0.01


def test_a_box_beside_a_placed_one_along_its_fingers_has_no_place_and_across_it_has():
    """Slots 50 mm apart along the box's 40 mm side: beside a placed box the open fingers (closing
    along that side, the slot's own yaw; a box has no other) have no room — no yaw is offered —
    while a box in the row 60 mm across leaves it (the fingers' half width is 12.5 mm)."""
    tray = TrayConfig(center=[0.35, 0.40, 0.15], size=[0.16, 0.12, 0.01],
                      slots=[SlotConfig(offset=list(o)) for o in ((-0.05, -0.03), (0.0, -0.03), (0.05, -0.03),
                                                                  (0.0, 0.03))])
    parts = [PartConfig(name=f"box_{k}", shape="box", size=list(BOX.size), mass=0.2) for k in range(3)]
    pick = PickConfig(tray=tray, parts=parts,
                      tasks=[PickTaskConfig(part="box_0", slot=0, place_yaw=0.0),
                             PickTaskConfig(part="box_1", slot=2, place_yaw=math.pi),
                             PickTaskConfig(part="box_2", slot=3, place_yaw=0.0)])
    from ptint_drake.worlds.pick.cell import place_point
    middle = place_point(pick, "slot", 1, BOX)
    assert puts(BOX, middle, 0.0, math.pi, in_tray(pick, [0, 1]), WSG, MARGIN) == []
    assert puts(BOX, middle, 0.0, math.pi, in_tray(pick, [0]), WSG, MARGIN) == []
    assert puts(BOX, middle, 0.0, math.pi, in_tray(pick, [2]), WSG, MARGIN) == [pytest.approx(math.pi)]
    # the disc of the old check (its half diagonal, 25 mm) would refuse line_two_belts' own yaw:
    # cubes 50 mm apart, the fingers' outer face 27 mm out, the neighbour's face 35 mm: 8 mm clear
    cube = CUBE.size[0] + MARGIN
    assert tray_clearance(np.zeros(3), 0.0, cube, (0.006, 0.02), _rect((0.05, 0.0), 0.0, CUBE.size)) == \
        pytest.approx(0.008)
    assert 0.008 >= FINGER_MARGIN
