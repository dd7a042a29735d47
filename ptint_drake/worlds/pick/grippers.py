"""The bundled grippers' datasheet limits and the arms' rated payloads (models/README.md gives
every number's source), and the checks built on them.

``DATASHEETS``: per bundled gripper (``pick.gripper.model``), the grip-force range (N, per jaw:
the force each jaw presses on the part) and the jaw-speed range (m/s) its datasheet allows.  The
RV-M1 hand (``rvm1_gripper``) has no datasheet: only positive values are required of it.
``RATED_PAYLOAD``: the bundled arms' rated payload including the hand (kg).

``check_gripper`` — a one-line ScenarioError naming ``pick.gripper.max_force`` or
``pick.gripper.speed`` outside the model's range; ``payload_warnings`` — before the run, a warning
naming the masses when the gripper plus a part weigh more than the arm's rated payload.
"""

from __future__ import annotations

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
