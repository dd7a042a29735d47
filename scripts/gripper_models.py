"""Writes the real-size gripper models of issue 45 (models/schunk_wsg_50_110_full.sdf,
models/robotiq_2f_85_full.sdf, models/panda_hand.sdf) from the table in
``ptint_drake.systems.hand.datasheets.FULL_SIZE`` (every number cited in models/README.md, section
"Real-size grippers").

They follow ``rvm1_gripper.sdf``'s conventions (frame ``fingertip_center``, z = approach, x = across
the fingers; prismatic ``left_finger_joint`` / ``right_finger_joint`` = each pad face's distance from
the centre plane) with the housing at its datasheet height: the model's flange (link
``gripper_base``'s origin, z = 0) sits on the arm's flange and ``fingertip_center`` is
``housing height + FINGER_DROP`` beyond it.  The arm models carry a frame ``<gripper>_tip`` at the
same place (scripts/arm_models.py), which the pick world welds ``fingertip_center`` to.

    .venv/bin/python scripts/gripper_models.py          # rewrites the three files
    .venv/bin/python scripts/gripper_models.py --check  # exit 1 if a file differs
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from generated_files import write_or_check  # (scripts/ is on sys.path when a script runs)

from ptint_drake.systems.hand.datasheets import FULL_SIZE, FullSizeGripper

MODELS = Path(__file__).resolve().parent.parent / "models"
FINGER_MASS = 0.02  # kg each: this project's fingers (as rvm1_gripper's; models/README.md)
_POINT = ("<drake:point_contact_stiffness>1e5</drake:point_contact_stiffness>"
          "<drake:hunt_crossley_dissipation>5</drake:hunt_crossley_dissipation>")


def _props(mu: float, pad: bool) -> str:
    hydro = ("<drake:compliant_hydroelastic/><drake:hydroelastic_modulus>1e6</drake:hydroelastic_modulus>"
             "<drake:mesh_resolution_hint>0.005</drake:mesh_resolution_hint>" if pad else
             "<drake:rigid_hydroelastic/>")
    return (f"<drake:proximity_properties><drake:mu_dynamic>{mu:g}</drake:mu_dynamic>"
            f"<drake:mu_static>{mu:g}</drake:mu_static>{_POINT}{hydro}</drake:proximity_properties>")


def _box(name: str, pose: str, size: str, color: str, mu: float, pad: bool = False,
         collision_pose: str = "", collision_size: str = "") -> str:
    return (f'      <visual name="{name}"><pose>{pose}</pose><geometry><box><size>{size}</size></box>'
            f'</geometry><material><diffuse>{color}</diffuse></material></visual>\n'
            f'      <collision name="{name}"><pose>{collision_pose or pose}</pose><geometry><box><size>'
            f'{collision_size or size}</size></box></geometry>\n        {_props(mu, pad)}</collision>\n')


def _finger(g: FullSizeGripper, side: str, sign: float) -> str:
    s = sign
    return (f'    <link name="{side}_finger">\n'
            '      <pose relative_to="fingertip_center">0 0 0 0 0 0</pose>\n'
            f'      <inertial><pose>{s * 0.004:g} 0 -0.0125 0 0 0</pose><mass>{FINGER_MASS:g}</mass>'
            "<inertia><ixx>4.04e-06</ixx><iyy>3.48e-06</iyy><izz>7.73e-07</izz><ixy>0</ixy><ixz>0</ixz>"
            "<iyz>0</iyz></inertia></inertial>\n"
            + _box("stem", f"{s * 0.004:g} 0 -0.0225 0 0 0", "0.008 0.02 0.025", "0.3 0.3 0.32 1", 0.5,
                   collision_pose=f"{s * 0.0045:g} 0 -0.0225 0 0 0", collision_size="0.007 0.02 0.025")
            + _box("pad", f"{s * 0.003:g} 0 0 0 0 0", "0.006 0.02 0.02", "0.1 0.5 0.85 1", 1.0, pad=True)
            + "    </link>\n"
            f'    <joint name="{side}_finger_joint" type="prismatic">\n      <parent>gripper_base</parent>'
            f'<child>{side}_finger</child>\n      <axis><xyz expressed_in="fingertip_center">{s:g} 0 0</xyz>'
            f"<limit><lower>0</lower><upper>{g.stroke / 2:g}</upper><effort>{g.force[1]:g}</effort>"
            f"<velocity>{g.speed[1]:g}</velocity></limit></axis>\n    </joint>\n")


def sdf(g: FullSizeGripper) -> str:
    """The SDFormat text of one real-size gripper."""
    lx, ly, h = g.housing
    m = g.mass - 2 * FINGER_MASS
    ixx, iyy, izz = (m * (ly ** 2 + h ** 2) / 12, m * (lx ** 2 + h ** 2) / 12, m * (lx ** 2 + ly ** 2) / 12)
    housing = f"{lx:g} {ly:g} {h:g}"
    return (f'<?xml version="1.0"?>\n<!--\n  {g.title}, at its real size (issue 45), written by\n'
            "  scripts/gripper_models.py from ptint_drake.systems.hand.datasheets.FULL_SIZE; every number's\n"
            '  source is in models/README.md, section "Real-size grippers".  Model frame = the gripper\'s\n'
            f"  flange; fingertip_center {g.tip_depth:g} m beyond it, turned {g.yaw_deg:g} deg about the\n"
            "  approach.\n"
            '-->\n<sdf version="1.9" xmlns:drake="http://drake.mit.edu">\n'
            f'  <model name="{g.name}">\n    <link name="gripper_base">\n'
            f"      <pose>0 0 0 0 0 {g.yaw_rad:.12g}</pose>\n"
            f"      <inertial><pose>0 0 {h / 2:g} 0 0 0</pose><mass>{m:g}</mass><inertia><ixx>{ixx:.6g}</ixx>"
            f"<iyy>{iyy:.6g}</iyy><izz>{izz:.6g}</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>\n"
            + _box("palm", f"0 0 {h / 2:g} 0 0 0", housing, "0.75 0.75 0.78 1", 0.5)
            + "    </link>\n"
            f'    <frame name="fingertip_center" attached_to="gripper_base"><pose>0 0 {g.tip_depth:g} 0 0 0'
            "</pose></frame>\n"
            + _finger(g, "left", -1.0) + _finger(g, "right", 1.0) + "  </model>\n</sdf>\n")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare instead of writing")
    args = parser.parse_args(argv)
    files = {MODELS / f"{g.name}.sdf": sdf(g) for g in FULL_SIZE.values()}
    return write_or_check(files, args.check, "scripts/gripper_models.py")


if __name__ == "__main__":
    sys.exit(main())
