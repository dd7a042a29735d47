"""Arms the package has never seen, as URDF text: a 3-DOF arm with a shoulder offset and other
lengths and masses (``OFFSET_ARM``, frame ``hand``), and a 4-DOF redundant one (``REDUNDANT_ARM``)."""


def _link(name, mass, com, size):
    return f"""
  <link name="{name}">
    <inertial><origin xyz="{com}"/><mass value="{mass}"/>
      <inertia ixx="{size}" ixy="0" ixz="0" iyy="{size}" iyz="0" izz="{size}"/></inertial>
  </link>"""


def _joint(name, parent, child, xyz, axis):
    return f"""
  <joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
    <origin xyz="{xyz}"/><axis xyz="{axis}"/><limit effort="100" lower="-3" upper="3" velocity="5"/>
    <dynamics damping="0.5"/></joint>
  <transmission type="SimpleTransmission" name="{name}_t">
    <actuator name="{name}_m"/><joint name="{name}"/><mechanicalReduction>1</mechanicalReduction>
  </transmission>"""


# A 3-DOF arm with a shoulder offset and other lengths and masses, and a 4-DOF redundant arm.
OFFSET_ARM = ("""<?xml version="1.0"?><robot name="offset_arm">""" + _link("base", 5, "0 0 0", 0.05)
              + """<joint name="weld" type="fixed"><parent link="world"/><child link="base"/></joint>"""
              + _link("l1", 2.0, "0 0 0.1", 0.01) + _joint("j1", "base", "l1", "0 0 0.4", "0 0 1")
              + _link("l2", 2.5, "0 0 0.17", 0.02) + _joint("j2", "l1", "l2", "0 0.06 0", "0 1 0")
              + _link("l3", 1.5, "0.15 0 0", 0.01) + _joint("j3", "l2", "l3", "0 0 0.35", "0 1 0")
              + """<link name="hand"/><joint name="hand_fix" type="fixed"><parent link="l3"/>
                 <child link="hand"/><origin xyz="0.3 0 0"/></joint></robot>""")
REDUNDANT_ARM = OFFSET_ARM.replace("offset_arm", "redundant_arm").replace(
    """<link name="hand"/><joint name="hand_fix" type="fixed"><parent link="l3"/>
                 <child link="hand"/><origin xyz="0.3 0 0"/></joint>""",
    _link("l4", 0.5, "0.05 0 0", 0.002) + _joint("j4", "l3", "l4", "0.2 0 0", "0 1 0")
    + """<link name="hand"/><joint name="hand_fix" type="fixed"><parent link="l4"/>
         <child link="hand"/><origin xyz="0.1 0 0"/></joint>""")
