"""The bundled grippers' datasheet limits and the arms' rated payloads (models/README.md gives
every number's source), and the checks built on them.

``DATASHEETS``: per bundled gripper (``pick.gripper.model``), the grip-force range (N, per jaw:
the force each jaw presses on the part) and the jaw-speed range (m/s) its datasheet allows.  The
RV-M1 hand (``rvm1_gripper``) has no datasheet: only positive values are required of it.
``RATED_PAYLOAD``: the bundled arms' rated payload including the hand (kg).
``FULL_SIZE``: the real-size grippers of issue 45 (``scripts/gripper_models.py`` writes their SDFormat
files from it, ``scripts/arm_models.py`` a frame ``<name>_tip`` on each industrial arm's flange).

``check_gripper`` — a one-line ScenarioError naming ``pick.gripper.max_force`` or
``pick.gripper.speed`` outside the model's range; ``payload_warnings`` — before the run, a warning
naming the masses when the gripper plus a part weigh more than the arm's rated payload.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ptint_drake.config.errors import ScenarioError


@dataclass(frozen=True)
class Datasheet:
    """A gripper's published ranges: grip force per jaw (N) and jaw speed (m/s), both inclusive."""

    force: tuple
    speed: tuple


DATASHEETS = {
    # Schunk WSG 50-110: 5-80 N grip force, up to 420 mm/s (models/README.md)
    "schunk_wsg_50_110": Datasheet(force=(5.0, 80.0), speed=(0.0, 0.42)),
    # Robotiq 2F-85: 20-235 N grip force, 20-150 mm/s closing speed (models/README.md)
    "robotiq_2f_85": Datasheet(force=(20.0, 235.0), speed=(0.02, 0.15)),
}


@dataclass(frozen=True)
class FullSizeGripper:
    """A gripper at its datasheet size (models/README.md, "Real-size grippers"): total mass (kg,
    this project's 2 x 0.02 kg fingers included), housing box (across the jaws, along them, height
    from the flange; m), full stroke (m), grip-force and per-jaw speed ranges (N, m/s), and the
    turn of the jaws about the approach axis relative to the arm's flange (deg)."""

    name: str
    title: str
    mass: float
    housing: tuple
    stroke: float
    force: tuple
    speed: tuple
    yaw_deg: float = 0.0

    @property
    def tip_depth(self) -> float:
        """The fingertip centre's distance from the flange (m): housing height + ``FINGER_DROP``."""
        return round(self.housing[2] + FINGER_DROP, 6)

    @property
    def yaw_rad(self) -> float:
        return math.radians(self.yaw_deg)


# m: the fingertip centre below the housing's far face (25 mm stems + half the 20 mm pads, as
# rvm1_gripper's fingers; this project's fingers, models/README.md)
FINGER_DROP = 0.035
FULL_SIZE = {g.name: g for g in (
    # Weiss Robotics / Schunk WSG 50-110: 1.2 kg, 146 x 50 x 72.5 mm housing, 110 mm stroke, 5-80 N,
    # up to 420 mm/s (datasheet; models/README.md)
    FullSizeGripper("schunk_wsg_50_110_full", "Schunk WSG 50-110", 1.2, (0.146, 0.05, 0.0725), 0.110,
                    (5.0, 80.0), (0.0, 0.42)),
    # Robotiq 2F-85: 0.925 kg, 85 mm stroke, 20-235 N, 20-150 mm/s, fingertips about 0.15 m from the
    # coupling face (manual section 6.1; models/README.md), modelled as parallel jaws
    FullSizeGripper("robotiq_2f_85_full", "Robotiq 2F-85", 0.925, (0.10, 0.06, 0.115), 0.085,
                    (20.0, 235.0), (0.02, 0.15)),
    # Franka Hand: 0.73 kg, 80 mm stroke, 70 N continuous grasping force, fingertip centre 0.1034 m
    # from the flange turned -45 deg about it (Franka's FCI specifications; models/README.md)
    FullSizeGripper("panda_hand", "Franka Hand (Panda)", 0.73, (0.20, 0.06, 0.0684), 0.08,
                    (0.0, 70.0), (0.0, 0.05), yaw_deg=-45.0),
)}
DATASHEETS.update({name: Datasheet(force=g.force, speed=g.speed) for name, g in FULL_SIZE.items()})

# kg, including the hand: the Mitsubishi RV-M1's rated payload (models/README.md); the 6-joint
# model is hypothetical, in the RV-M1's size, and is held to the same.  The iiwa 14 R820's, the
# Panda's and the UR5e's rated payloads at the flange (their data sheets; models/README.md, issue 45)
RATED_PAYLOAD = {"rvm1": 1.2, "rvm1_5dof": 1.2, "rvm1_6dof": 1.2, "iiwa14": 14.0, "panda": 3.0,
                 "ur5e": 5.0}


def check_gripper(gripper) -> None:
    """ScenarioError naming the first of ``pick.gripper``'s fields outside its model's datasheet
    range (``DATASHEETS``; a gripper without a datasheet only needs positive values)."""
    sheet = DATASHEETS.get(gripper.model)
    if sheet is None:
        return
    for name, value, (low, high), unit in (("max_force", gripper.max_force, sheet.force, "N"),
                                           ("speed", gripper.speed, sheet.speed, "m/s")):
        if not low <= value <= high or (low == 0.0 and value <= 0.0):
            bounds = f"{low:g} … {high:g}" if low > 0.0 else f"up to {high:g}"
            raise ScenarioError(f"pick.gripper.{name}: {value:g} {unit} is outside the {gripper.model} "
                                f"datasheet's range ({bounds} {unit})")


def payload_warnings(arm_model: str, gripper_name: str, gripper_kg: float, parts) -> list[str]:
    """One warning per part whose mass with the gripper's exceeds the arm's rated payload (arms
    of ``RATED_PAYLOAD`` only)."""
    rated = RATED_PAYLOAD.get(arm_model)
    if rated is None:
        return []
    return [f"payload: gripper {gripper_name} {gripper_kg:.2f} kg + part {p.name!r} {p.mass:.2f} kg = "
            f"{gripper_kg + p.mass:.2f} kg exceeds the {arm_model}'s rated payload of {rated:g} kg "
            f"(including the hand)" for p in parts if gripper_kg + p.mass > rated + 1e-9]


def check_mount(gripper_model: str, end_effector: str, arm_has_frame) -> None:
    """ScenarioError when a real-size gripper (``FULL_SIZE``) and the arm's end-effector frame do
    not match: on an arm that carries the frame ``<gripper>_tip`` (the bundled industrial arms),
    ``robot.end_effector`` must be that frame (the gripper's flange then sits on the arm's), and a
    ``<name>_tip`` frame belongs to that gripper only.  ``arm_has_frame``: name → bool."""
    tips = {f"{name}_tip": name for name in FULL_SIZE}
    owner = tips.get(end_effector)
    if owner is not None and owner != gripper_model:
        raise ScenarioError(f"robot.end_effector: {end_effector!r} is the fingertip centre of {owner}, "
                            f"not of pick.gripper.model {gripper_model!r}")
    g = FULL_SIZE.get(gripper_model)
    if g is not None and end_effector != f"{g.name}_tip" and arm_has_frame(f"{g.name}_tip"):
        raise ScenarioError(f"robot.end_effector: {gripper_model}'s fingertips sit {g.tip_depth:g} m beyond "
                            f"the arm's flange: use the frame '{g.name}_tip', not {end_effector!r}")
