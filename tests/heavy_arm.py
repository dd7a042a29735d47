"""A heavy 6-joint arm written for the tests (not a real robot): about 15 kg, links 0.12–0.40 m,
effort limits 28–150 N·m, joint damping 1 N·m·s/rad.  With more joints than task dimensions it
is redundant for 3-D interception."""

_JOINTS = [  # name, parent, child, origin xyz of the joint in the parent, axis, effort (N·m)
    ("j1", "base", "l1", "0 0 0.12", "0 0 1", 150),
    ("j2", "l1", "l2", "0 0 0.10", "0 1 0", 150),
    ("j3", "l2", "l3", "0 0 0.40", "0 1 0", 80),
    ("j4", "l3", "l4", "0.35 0 0", "1 0 0", 40),
    ("j5", "l4", "l5", "0.12 0 0", "0 1 0", 28),
    ("j6", "l5", "l6", "0.12 0 0", "1 0 0", 28),
]
_LINKS = [  # name, mass (kg), centre of mass, principal inertia (kg·m²)
    ("l1", 4.0, "0 0 0.05", 0.02), ("l2", 4.0, "0 0 0.20", 0.06), ("l3", 3.0, "0.17 0 0", 0.035),
    ("l4", 1.5, "0.06 0 0", 0.004), ("l5", 1.5, "0.06 0 0", 0.004), ("l6", 1.0, "0.05 0 0", 0.002),
]


def heavy_arm_urdf() -> str:
    parts = ['<?xml version="1.0"?>\n<robot name="heavy6">', '<link name="base"/>',
             '<joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>']
    for name, mass, com, inertia in _LINKS:
        parts.append(f'<link name="{name}"><inertial><origin xyz="{com}"/><mass value="{mass}"/>'
                     f'<inertia ixx="{inertia}" ixy="0" ixz="0" iyy="{inertia}" iyz="0" '
                     f'izz="{inertia}"/></inertial></link>')
    for name, parent, child, xyz, axis, effort in _JOINTS:
        parts.append(
            f'<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="{xyz}"/><axis xyz="{axis}"/>'
            f'<limit effort="{effort}" lower="-3.0" upper="3.0" velocity="3.0"/>'
            f'<dynamics damping="1.0"/></joint>'
            f'<transmission type="SimpleTransmission" name="{name}_t"><actuator name="{name}_m"/>'
            f'<joint name="{name}"/><mechanicalReduction>1</mechanicalReduction></transmission>')
    parts.append('<link name="tool"/><joint name="tool_fix" type="fixed"><parent link="l6"/>'
                 '<child link="tool"/><origin xyz="0.10 0 0"/></joint></robot>')
    return "\n".join(parts)


def heavy_arm_scenario(urdf_path, K: float = 50.0) -> str:
    """A conveyor interception for the heavy arm (start pose: elbow up, wrist bent down)."""
    return f"""duration: 2.5
robot: {{model: {urdf_path}, end_effector: tool, initial_q_deg: [0.0, 0.0, 20.0, 0.0, 20.0, 0.0]}}
controller: {{K: {K}}}
interceptions:
  - {{start: 0.0, tf: 1.0, beta: 0.75,
     target: {{linear: {{start: [0.50, -0.12, 0.25], velocity: [0.0, 0.1, 0.0]}}}}}}
"""
