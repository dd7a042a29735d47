"""Writes models/iiwa14.urdf, models/panda.urdf and models/ur5e.urdf (issue 45) from the tables below.

Every number here is cited in models/README.md (one section per arm); the tables live only here.
Kinematics are Denavit-Hartenberg tables: the UR5e's and the iiwa's in the standard (distal)
convention, T_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i); the Panda's in Craig's modified (proximal)
convention, as Franka publishes it, T_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i) (each row holds
(a_{i-1}, d_i, α_{i-1})).  Link inertial data and shapes are given in DH frame i (the frame the
source uses); this script moves them into the URDF link frames.

    .venv/bin/python scripts/arm_models.py          # rewrites the three files
    .venv/bin/python scripts/arm_models.py --check  # exit 1 if a file differs from what it would write
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from generated_files import write_or_check  # (scripts/ is on sys.path when a script runs)

from ptint_drake.systems.hand.datasheets import FULL_SIZE

MODELS = Path(__file__).resolve().parent.parent / "models"
PI = math.pi


@dataclass(frozen=True)
class Shape:
    """A collision (and visual) primitive in DH frame i: a cylinder from ``a`` to ``b`` of radius
    ``r``, or a sphere of radius ``r`` at ``a`` (``b`` None)."""
    a: tuple
    b: tuple | None
    r: float


@dataclass(frozen=True)
class Link:
    """A moving link: mass (kg), centre of mass (m, DH frame i), inertia about the centre of mass
    (ixx, ixy, ixz, iyy, iyz, izz, kg m², axes of DH frame i) — None: a solid cylinder of this mass
    on the first shape's axis (the assumption stated in models/README.md)."""
    mass: float
    com: tuple
    shapes: tuple
    inertia: tuple | None = None


@dataclass(frozen=True)
class Joint:
    """A revolute joint: DH row (a, d, alpha), limits (rad, rad/s, N·m), damping (N·m·s/rad),
    reflected rotor inertia (kg m², through ``GEAR_RATIO``)."""
    a: float
    d: float
    alpha: float
    lower: float
    upper: float
    velocity: float
    effort: float
    damping: float
    reflected: float


@dataclass(frozen=True)
class Arm:
    name: str
    convention: str  # "standard" or "modified"
    header: str
    base_mass: float
    base_shapes: tuple
    joints: tuple
    links: tuple
    payload_kg: float
    datasheet_mass: float
    tool_d: float = 0.0  # modified DH: the flange row's d (along z of the last frame)
    colors: tuple = field(default=("0.9 0.9 0.9 1", "0.35 0.35 0.38 1"))


GEAR_RATIO = 100.0  # assumption: every joint; the rotor inertia is reflected / ratio²


def _deg(values):
    return tuple(math.radians(v) for v in values)


# ---------------------------------------------------------------------------------------------
# KUKA LBR iiwa 14 R820.  Lengths 0.36 / 0.42 / 0.40 / 0.126 m, ranges, speeds and torques: KUKA's
# LBR iiwa data sheet.  The DH table (standard) is this project's reading of those lengths with
# the axes J1 +z, J2 +y, J3 +z, J4 -y, J5 +z, J6 +y, J7 +z at q = 0 (arm straight up).
# Link masses and inertias: ASSUMPTIONS (solid cylinders summing to the data sheet's 29.9 kg).
_IIWA_RANGE = _deg((170, 120, 170, 120, 170, 120, 175))
_IIWA_SPEED = _deg((85, 85, 100, 75, 130, 135, 135))
_IIWA_TORQUE = (320, 320, 176, 176, 110, 40, 40)
_IIWA_DH = ((0.0, 0.36, -PI / 2), (0.0, 0.0, PI / 2), (0.0, 0.42, PI / 2), (0.0, 0.0, -PI / 2),
            (0.0, 0.40, -PI / 2), (0.0, 0.0, PI / 2), (0.0, 0.126, 0.0))
_IIWA_DAMPING = (0.5, 0.5, 0.5, 0.5, 0.2, 0.2, 0.2)
_IIWA_REFLECTED = (0.4, 0.4, 0.4, 0.4, 0.2, 0.1, 0.1)


def _segment_link(mass, a, b, r, extra=()):
    com = tuple((np.add(a, b) / 2).tolist())
    return Link(mass, com, (Shape(a, b, r), *extra))


IIWA14 = Arm(
    name="iiwa14",
    convention="standard",
    header=("KUKA LBR iiwa 14 R820, written by ptint_drake's scripts/arm_models.py from KUKA's data sheet\n"
            "  (lengths, ranges, speeds, torques, 29.9 kg, 14 kg payload); link masses and inertias are\n"
            "  ASSUMPTIONS (solid cylinders summing to 29.9 kg); see models/README.md."),
    base_mass=6.0,
    base_shapes=(Shape((0, 0, 0), (0, 0, 0.16), 0.10),),
    joints=tuple(Joint(a, d, al, -rng, rng, v, t, dmp, refl) for (a, d, al), rng, v, t, dmp, refl
                 in zip(_IIWA_DH, _IIWA_RANGE, _IIWA_SPEED, _IIWA_TORQUE, _IIWA_DAMPING,
                        _IIWA_REFLECTED)),
    links=(
        _segment_link(4.8, (0, 0.20, 0), (0, 0, 0), 0.075),      # base top -> shoulder (frame 1: up = -y)
        _segment_link(4.8, (0, 0, 0), (0, 0, 0.20), 0.075),      # shoulder -> mid upper arm
        _segment_link(4.0, (0, -0.22, 0), (0, 0, 0), 0.07),      # mid upper arm -> elbow (frame 3: up = +y)
        _segment_link(3.8, (0, 0, 0), (0, 0, 0.20), 0.07),       # elbow -> mid forearm
        _segment_link(3.0, (0, 0.20, 0), (0, 0, 0), 0.065),      # mid forearm -> wrist (frame 5: up = -y)
        _segment_link(2.6, (0, 0, -0.06), (0, 0, 0.07), 0.065),  # wrist housing (J6/J7)
        _segment_link(0.9, (0, 0, -0.06), (0, 0, 0), 0.05),      # flange (frame 7 = the flange)
    ),
    payload_kg=14.0,
    datasheet_mass=29.9,
)

# ---------------------------------------------------------------------------------------------
# Franka Emika Panda.  Modified DH (a, d, alpha per row, flange d = 0.107 m), joint position,
# velocity and torque limits: Franka's "Robot and interface specifications".  Link 1-7 masses,
# centres of mass and inertias (about the centre of mass, in the DH frames): Gaz, Cognetti,
# Oliva, Robuffo Giordano, De Luca, IEEE RA-L 4(4) 2019, supplementary material tables VIII-IX.
# Link 0 (the base): ASSUMPTION, the data sheet's ~18 kg minus links 1-7 (16.06 kg).
_PANDA_DH = ((0.0, 0.333, 0.0), (0.0, 0.0, -PI / 2), (0.0, 0.316, PI / 2), (0.0825, 0.0, PI / 2),
             (-0.0825, 0.384, -PI / 2), (0.0, 0.0, PI / 2), (0.088, 0.0, PI / 2))
_PANDA_LOWER = (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973)
_PANDA_UPPER = (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973)
_PANDA_SPEED = (2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100)
_PANDA_TORQUE = (87, 87, 87, 87, 12, 12, 12)
_PANDA_DAMPING = (0.3, 0.3, 0.3, 0.3, 0.1, 0.1, 0.1)
_PANDA_REFLECTED = (0.2, 0.2, 0.2, 0.2, 0.05, 0.05, 0.05)
_GAZ_MASS = (4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522)
_GAZ_COM = ((3.875e-03, 2.081e-03, 0.0), (-3.141e-03, -2.872e-02, 3.495e-03),
            (2.7518e-02, 3.9252e-02, -6.6502e-02), (-5.317e-02, 1.04419e-01, 2.7454e-02),
            (-1.1953e-02, 4.1065e-02, -3.8437e-02), (6.0149e-02, -1.4117e-02, -1.0517e-02),
            (1.0517e-02, -4.252e-03, 6.1597e-02))
_GAZ_INERTIA = ((7.0337e-01, -1.3900e-04, 6.7720e-03, 7.0661e-01, 1.9169e-02, 9.1170e-03),
                (7.9620e-03, -3.9250e-03, 1.0254e-02, 2.8110e-02, 7.0400e-04, 2.5995e-02),
                (3.7242e-02, -4.7610e-03, -1.1396e-02, 3.6155e-02, -1.2805e-02, 1.0830e-02),
                (2.5853e-02, 7.7960e-03, -1.3320e-03, 1.9552e-02, 8.6410e-03, 2.8323e-02),
                (3.5549e-02, -2.1170e-03, -4.0370e-03, 2.9474e-02, 2.2900e-04, 8.6270e-03),
                (1.9640e-03, 1.0900e-04, -1.1580e-03, 4.3540e-03, 3.4100e-04, 5.4330e-03),
                (1.2516e-02, -4.2800e-04, -1.1960e-03, 1.0027e-02, -7.4100e-04, 4.8150e-03))
_PANDA_SHAPES = (
    (Shape((0, 0, -0.19), (0, 0, 0.05), 0.065),),                     # link 1 (frame 1 at z 0.333)
    (Shape((0, 0, -0.06), (0, 0, 0.06), 0.065), Shape((0, 0, 0), (0, -0.15, 0), 0.06)),
    (Shape((0, 0, -0.15), (0, 0, 0), 0.06), Shape((0, 0, 0), (0.0825, 0, 0), 0.055)),
    (Shape((0, 0, -0.06), (0, 0, 0.06), 0.06), Shape((0, 0, 0), (-0.0825, 0.1, 0), 0.055)),
    (Shape((0, 0, -0.27), (0, 0, 0), 0.055),),                        # forearm
    (Shape((0, 0, -0.05), (0, 0, 0.05), 0.055), Shape((0, 0, 0), (0.088, 0, 0), 0.05)),
    (Shape((0, 0, -0.03), (0, 0, 0.107), 0.045),),                    # wrist flange
)
PANDA = Arm(
    name="panda",
    convention="modified",
    header=("Franka Emika Panda, written by ptint_drake's scripts/arm_models.py from Franka's published\n"
            "  modified DH table and limits and the inertial parameters identified by Gaz et al. (IEEE RA-L\n"
            "  2019); the base link's mass is an ASSUMPTION; see models/README.md."),
    base_mass=2.0,
    base_shapes=(Shape((0, 0, 0), (0, 0, 0.14), 0.09),),
    joints=tuple(Joint(a, d, al, lo, up, v, t, dmp, refl) for (a, d, al), lo, up, v, t, dmp, refl
                 in zip(_PANDA_DH, _PANDA_LOWER, _PANDA_UPPER, _PANDA_SPEED, _PANDA_TORQUE,
                        _PANDA_DAMPING, _PANDA_REFLECTED)),
    links=tuple(Link(m, c, s, i) for m, c, s, i in zip(_GAZ_MASS, _GAZ_COM, _PANDA_SHAPES, _GAZ_INERTIA)),
    payload_kg=3.0,
    datasheet_mass=18.0,
    tool_d=0.107,
)

# ---------------------------------------------------------------------------------------------
# Universal Robots UR5e.  DH table (standard), link masses and centres of mass: UR's "DH
# parameters for calculations of kinematics and dynamics".  Ranges ±360°, speeds 180°/s, 20.6 kg,
# 5 kg payload: UR5e data sheet.  Torques: UR's joint size classes (size 3: 150 N·m for base,
# shoulder, elbow; size 1: 28 N·m for the wrists).  Inertias: ASSUMPTIONS (UR states them
# negligible for the UR5e and publishes none): solid cylinders on the link shapes.  Base link mass:
# ASSUMPTION, 20.6 kg minus links 1-6 (17.7 kg).
_UR_DH = ((0.0, 0.1625, PI / 2), (-0.425, 0.0, 0.0), (-0.3922, 0.0, 0.0), (0.0, 0.1333, PI / 2),
          (0.0, 0.0997, -PI / 2), (0.0, 0.0996, 0.0))
_UR_MASS = (3.761, 8.058, 2.846, 1.37, 1.3, 0.365)
_UR_COM = ((0, -0.02561, 0.00193), (0.2125, 0, 0.11336), (0.15, 0.0, 0.0265), (0, -0.0018, 0.01634),
           (0, 0.0018, 0.01634), (0, 0, -0.001159))
_UR_SHAPES = (
    (Shape((0, 0, -0.065), (0, 0, 0.075), 0.06), Shape((0, -0.075, 0), (0, 0, 0), 0.06)),  # shoulder
    (Shape((0, 0, 0.12), (0.425, 0, 0.12), 0.055), Shape((0.425, 0, 0.0), (0.425, 0, 0.18), 0.06)),
    (Shape((0, 0, 0.02), (0.3922, 0, 0.02), 0.045), Shape((0.3922, 0, -0.01), (0.3922, 0, 0.07), 0.05)),
    (Shape((0, 0, -0.045), (0, 0, 0.055), 0.045),),
    (Shape((0, 0, -0.045), (0, 0, 0.055), 0.045),),
    (Shape((0, 0, -0.03), (0, 0, 0.0), 0.04),),
)
_UR_TORQUE = (150, 150, 150, 28, 28, 28)
_UR_DAMPING = (0.5, 0.5, 0.5, 0.2, 0.2, 0.2)
_UR_REFLECTED = (0.3, 0.3, 0.3, 0.05, 0.05, 0.05)
UR5E = Arm(
    name="ur5e",
    convention="standard",
    header=("Universal Robots UR5e, written by ptint_drake's scripts/arm_models.py from UR's published\n"
            "  DH table, link masses and centres of mass and the UR5e data sheet (ranges, speeds, 20.6 kg,\n"
            "  5 kg payload); inertias and the base link's mass are ASSUMPTIONS; see models/README.md.\n"
            "  The world frame is UR's DH frame 0 (UR's controller base frame is turned 180 deg about z)."),
    base_mass=2.9,
    base_shapes=(Shape((0, 0, 0), (0, 0, 0.09), 0.075),),
    joints=tuple(Joint(a, d, al, -2 * PI, 2 * PI, PI, t, dmp, refl) for (a, d, al), t, dmp, refl
                 in zip(_UR_DH, _UR_TORQUE, _UR_DAMPING, _UR_REFLECTED)),
    links=tuple(Link(m, c, s) for m, c, s in zip(_UR_MASS, _UR_COM, _UR_SHAPES)),
    payload_kg=5.0,
    datasheet_mass=20.6,
)

ARMS = (IIWA14, PANDA, UR5E)


# ---------------------------------------------------------------------------------------------
def _rx(alpha: float) -> np.ndarray:
    c, s = math.cos(alpha), math.sin(alpha)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _cylinder_inertia(mass: float, shape: Shape) -> np.ndarray:
    """A solid cylinder's inertia about its centre, in the frame of ``shape``."""
    axis = np.subtract(shape.b, shape.a)
    length = float(np.linalg.norm(axis))
    u = axis / length
    axial = mass * shape.r ** 2 / 2.0
    transverse = mass * (3.0 * shape.r ** 2 + length ** 2) / 12.0
    return transverse * np.eye(3) + (axial - transverse) * np.outer(u, u)


def _inertia_matrix(values) -> np.ndarray:
    ixx, ixy, ixz, iyy, iyz, izz = values
    return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])


def _fmt(x: float) -> str:
    value = float(x)
    if abs(value) < 1e-15:
        return "0"
    return repr(value)


def _vec(v) -> str:
    return " ".join(_fmt(x) for x in v)


def _rpy_of_z_to(u) -> tuple:
    """Roll-pitch-yaw that turns +z onto the unit vector ``u`` (for a cylinder along ``u``)."""
    u = np.asarray(u, dtype=float) / np.linalg.norm(u)
    pitch = math.atan2(math.hypot(u[0], u[1]), u[2])
    yaw = math.atan2(u[1], u[0]) if math.hypot(u[0], u[1]) > 1e-12 else 0.0
    return (0.0, pitch, yaw)


PROXIMITY = """      <drake:proximity_properties>
        <drake:rigid_hydroelastic/>
        <drake:mesh_resolution_hint value="0.01"/>
        <drake:mu_dynamic value="0.5"/>
        <drake:mu_static value="0.5"/>
        <drake:point_contact_stiffness value="1e5"/>
        <drake:hunt_crossley_dissipation value="5"/>
      </drake:proximity_properties>"""


def _geometry(shape: Shape, R: np.ndarray, p: np.ndarray) -> tuple[str, str, str]:
    """(origin xyz, origin rpy, geometry element) of ``shape`` given in a frame at (R, p) of the link."""
    a = p + R @ np.asarray(shape.a, dtype=float)
    if shape.b is None:
        return _vec(a), "0 0 0", f'<sphere radius="{_fmt(shape.r)}"/>'
    b = p + R @ np.asarray(shape.b, dtype=float)
    length = float(np.linalg.norm(b - a))
    return (_vec((a + b) / 2), _vec(_rpy_of_z_to(b - a)),
            f'<cylinder radius="{_fmt(shape.r)}" length="{_fmt(length)}"/>')


def _link_xml(name: str, mass: float, com, inertia: np.ndarray, shapes, R, p, color: str) -> str:
    rows = [f'  <link name="{name}">', "    <inertial>",
            f'      <origin xyz="{_vec(com)}"/>', f'      <mass value="{_fmt(mass)}"/>',
            '      <inertia ixx="{}" ixy="{}" ixz="{}" iyy="{}" iyz="{}" izz="{}"/>'.format(
                *(_fmt(inertia[i, j]) for i, j in ((0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)))),
            "    </inertial>"]
    for k, shape in enumerate(shapes):
        xyz, rpy, geometry = _geometry(shape, R, p)
        rows += ["    <visual>", f'      <origin xyz="{xyz}" rpy="{rpy}"/>',
                 f"      <geometry>{geometry}</geometry>",
                 f'      <material name="{name}_{k}"><color rgba="{color}"/></material>', "    </visual>",
                 f'    <collision name="{name}_{k}">', f'      <origin xyz="{xyz}" rpy="{rpy}"/>',
                 f"      <geometry>{geometry}</geometry>", PROXIMITY, "    </collision>"]
    rows.append("  </link>")
    return "\n".join(rows)


def urdf(arm: Arm) -> str:
    """The URDF text of ``arm``."""
    total = arm.base_mass + sum(link.mass for link in arm.links)
    out = ['<?xml version="1.0"?>', "<!--", f"  {arm.header}",
           f"  Rated payload: {arm.payload_kg:g} kg at the flange (data sheet); total mass "
           f"{total:.2f} kg (data sheet {arm.datasheet_mass:g} kg).",
           "  Joint damping, rotor inertias and gear ratios are ASSUMPTIONS (models/README.md).",
           "  Frame `tool`: the flange centre, z out of the flange (the approach direction).",
           "  Generated file: edit scripts/arm_models.py instead.", "-->", f'<robot name="{arm.name}">']
    eye = np.eye(3)
    out.append(_link_xml("base", arm.base_mass, (0, 0, arm.base_shapes[0].b[2] / 2),
                         _cylinder_inertia(arm.base_mass, arm.base_shapes[0]), arm.base_shapes, eye,
                         np.zeros(3), arm.colors[1]))
    out += ['  <joint name="world_weld" type="fixed">', '    <parent link="world"/>',
            '    <child link="base"/>', "  </joint>"]
    parent = "base"
    # the fixed transform from the parent link's URDF frame to joint i's frame
    origin_R, origin_p = eye, np.zeros(3)
    for i, (joint, link) in enumerate(zip(arm.joints, arm.links), start=1):
        if arm.convention == "modified":
            origin_R = _rx(joint.alpha)
            origin_p = np.array([joint.a, 0.0, 0.0]) + origin_R @ np.array([0.0, 0.0, joint.d])
            R_dh, p_dh = eye, np.zeros(3)  # link frame = DH frame i
        else:
            # URDF frame of link i = DH frame i-1 turned by θ_i; DH frame i is Tz(d) Tx(a) Rx(α) from it
            R_dh, p_dh = _rx(joint.alpha), np.array([joint.a, 0.0, joint.d])
        name = f"link{i}"
        com = p_dh + R_dh @ np.asarray(link.com, dtype=float)
        inertia = (_cylinder_inertia(link.mass, link.shapes[0]) if link.inertia is None
                   else _inertia_matrix(link.inertia))
        inertia = R_dh @ inertia @ R_dh.T
        out.append(_link_xml(name, link.mass, com, inertia, link.shapes, R_dh, p_dh,
                             arm.colors[i % 2 == 0]))
        rpy = (math.atan2(origin_R[2, 1], origin_R[2, 2]), 0.0, 0.0)
        out += [f'  <joint name="joint{i}" type="revolute">', f'    <parent link="{parent}"/>',
                f'    <child link="{name}"/>', f'    <origin xyz="{_vec(origin_p)}" rpy="{_vec(rpy)}"/>',
                '    <axis xyz="0 0 1"/>',
                f'    <limit lower="{_fmt(joint.lower)}" upper="{_fmt(joint.upper)}" '
                f'effort="{_fmt(joint.effort)}" velocity="{_fmt(joint.velocity)}"/>',
                f'    <dynamics damping="{_fmt(joint.damping)}"/>', "  </joint>"]
        if arm.convention == "standard":
            origin_R, origin_p = R_dh, p_dh
        parent = name
    if arm.convention == "modified":
        tool_p, tool_rpy = np.array([0.0, 0.0, arm.tool_d]), (0.0, 0.0, 0.0)
    else:
        tool_p, tool_rpy = origin_p, (math.atan2(origin_R[2, 1], origin_R[2, 2]), 0.0, 0.0)
    out += ['  <link name="tool"/>', '  <joint name="tool_weld" type="fixed">',
            f'    <parent link="{parent}"/>', '    <child link="tool"/>',
            f'    <origin xyz="{_vec(tool_p)}" rpy="{_vec(tool_rpy)}"/>', "  </joint>"]
    out.append("  <!-- fingertip centres of the real-size grippers mounted on the flange (the pick world "
               "welds their fingertip_center here; scripts/gripper_models.py) -->")
    out += [f'  <frame name="{g.name}_tip" link="tool" xyz="0 0 {_fmt(g.tip_depth)}" '
            f'rpy="0 0 {_fmt(g.yaw_rad)}"/>' for g in FULL_SIZE.values()]
    out.append(f"  <!-- transmissions: gear ratio {GEAR_RATIO:g}, rotor inertia = reflected inertia / "
               "ratio^2 (assumptions) -->")
    for i, joint in enumerate(arm.joints, start=1):
        rotor = joint.reflected / GEAR_RATIO ** 2
        out += [f'  <transmission type="SimpleTransmission" name="joint{i}_trans">',
                f'    <actuator name="joint{i}_motor"><drake:rotor_inertia value="{_fmt(rotor)}"/>'
                f'<drake:gear_ratio value="{_fmt(GEAR_RATIO)}"/></actuator>',
                f'    <joint name="joint{i}"/>', "    <mechanicalReduction>1</mechanicalReduction>",
                "  </transmission>"]
    out.append("</robot>")
    return "\n".join(out) + "\n"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    args = parser.parse_args(argv)
    files = {MODELS / f"{arm.name}.urdf": urdf(arm) for arm in ARMS}
    return write_or_check(files, args.check, "scripts/arm_models.py")


if __name__ == "__main__":
    sys.exit(main())
