"""A line scenario's checks before its run (one line naming the field, exit 2) and its warnings.

``check_line_scenario``: the pose sensor (no ``measurement``) or the rendered camera
(``measurement.sensor: rgbd``, ``seen``; its camera perceives the line's own belts and each track
carries its own filter: ``camera.belts`` and an ``estimator`` other than ``auto`` refused), the
cell (``config.check_pick_parts``), the ``pick.line`` block (``config.line.check_line`` with the
gripper's stroke read from its model), the pool on its belts, and every slot of the catalog
reachable from above (Drake's IK from the start posture) at half its kind's height and
``lift_height`` above — a slot out of reach is named ``pick.tray.slots[j]``, an outgoing belt
with no point in reach ``pick.line.catalog[k].belt``.

``line_warnings``: the arrival rate against the arm's capacity — the min-tf model's estimate
(``line.cycle.estimate``, picks per minute): above it, a warning with the numbers, and the run goes
on; a cell where the model finds no cycle at a reach window's middle (``NoTfFits``), a warning
naming why, and the run goes on.  The estimate, not a measurement: a measured throughput belongs
to one cell and one commit (the surplus line's is measured by ``scripts/line_capacity.py``,
docs/pick_place.md "The line's capacity").  A tray slot where the open fingers come down beside a belt
(``obstacles.slot_warnings``): a warning naming the slot and the belt.  A camera that sees no
point of the line's belts' centre lines (every
``VIEW_STEP``): a warning (every part will be ``not seen``), and the run goes on.
"""

from __future__ import annotations

import numpy as np
from pydrake.multibody.plant import MultibodyPlant

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.line import check_line
from ptint_drake.config.part_shape import part_height
from ptint_drake.config.pick import PickTaskConfig
from ptint_drake.robot.plant import nominal_plant
from ptint_drake.robot.reachability import inverse_kinematics
from ptint_drake.systems.perception.rgbd_camera import camera_info, camera_pose, describe_pose, in_view
from ptint_drake.worlds.pick.config import check_pick_parts
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.line.cycle import estimate
from ptint_drake.worlds.pick.line.driver import cycle_time
from ptint_drake.worlds.pick.line.plan import line_plan
from ptint_drake.worlds.pick.obstacles import slot_warnings
from ptint_drake.worlds.pick.phase_time import NoTfFits
from ptint_drake.worlds.pick.scene import (BIN_DROP_CLEARANCE, AddGripper, belt_frame, gripper_stroke,
                                          slot_pose)

VIEW_STEP = 0.01  # m, along a belt's centre line: the points a camera must see one of
OUT_STEP = 0.05  # m, along an outgoing belt's centre line: the points one of which the arm must reach

__all__ = ["check_line_scenario", "line_plan", "line_warnings", "stroke_of"]


def stroke_of(gripper) -> float:
    """m: the largest opening of the gripper ``gripper`` (a ``GripperConfig``), from its model."""
    plant = MultibodyPlant(0.001)
    instance = AddGripper(plant, plant.world_frame(), gripper)
    return gripper_stroke(plant, instance)


def check_line_scenario(scenario) -> None:
    """ScenarioError naming the first bad field of a line scenario (module docstring)."""
    m = scenario.measurement
    if m is not None and m.camera is not None and m.camera.belts:
        raise ScenarioError("measurement.camera.belts: a line's camera perceives the line's own belts "
                            "(pick.belts): leave belts out")
    if m is not None and m.estimator != "auto":
        raise ScenarioError(f"measurement.estimator: a line's tracks each carry their own filter "
                            f"(systems.perception.tracks): leave estimator auto, got {m.estimator!r}")
    pick = scenario.pick
    check_pick_parts(pick)
    task = PickTaskConfig()
    check_line(pick, scenario.duration, stroke_of(pick.gripper), task.margin)
    expanded, _ = line_scenario(scenario)
    check_pick_parts(expanded.pick)
    arm = nominal_plant(scenario)
    frame = arm.GetFrameByName(scenario.robot.end_effector)
    guess = np.radians(scenario.robot.initial_q_deg)
    bins = {b.name: (j, b) for j, b in enumerate(pick.bins)}
    for k, kind in enumerate(pick.line.catalog):
        height = part_height(kind.shape, kind.size)
        if kind.belt:
            _check_out_belt(arm, frame, guess, pick, k, height, task.lift_height)
        if kind.bin:
            j, box = bins[kind.bin]
            x = np.asarray(box.center, dtype=float) + [0.0, 0.0, box.size[2] + BIN_DROP_CLEARANCE
                                                       + height / 2]
            if inverse_kinematics(arm, frame, x, guess, down=True) is None:
                raise ScenarioError(f"pick.bins[{j}] (its center and depth): {np.round(x, 3).tolist()} m is "
                                    f"outside what the arm reaches from above")
        for j in kind.slots:
            x = slot_pose(pick.tray, j).translation() + [0.0, 0.0, height / 2]
            for where in (x, x + [0.0, 0.0, task.lift_height]):
                if inverse_kinematics(arm, frame, where, guess, down=True) is None:
                    raise ScenarioError(f"pick.tray.slots[{j}] (pick.tray.center and the slot's offset): "
                                        f"{np.round(where, 3).tolist()} m is outside what the arm reaches "
                                        f"from above")


def _check_out_belt(arm, frame, guess, pick, k: int, height: float, lift: float) -> None:
    """ScenarioError naming ``pick.line.catalog[k].belt`` where no point of that outgoing belt's
    centre line (every ``OUT_STEP``) is reachable from above at half the kind's height and
    ``lift`` above (Drake's IK, as the reach windows)."""
    name = pick.line.catalog[k].belt
    belt = next(b for b in pick.belts if b.name == name)
    for s in np.arange(-belt.length / 2, belt.length / 2 + 1e-9, OUT_STEP):
        x = belt_frame(belt).multiply(np.array([s, 0.0, height / 2]))
        q = inverse_kinematics(arm, frame, x, guess, down=True)
        if q is not None and inverse_kinematics(arm, frame, x + [0.0, 0.0, lift], q, down=True) is not None:
            return
    raise ScenarioError(f"pick.line.catalog[{k}].belt: no point of belt {name!r} (its center "
                        f"{list(belt.center)}) is within what the arm reaches from above")


def _blind(scenario) -> list[str]:
    """A camera that sees no point of the line's belts (module docstring)."""
    m, pick = scenario.measurement, scenario.pick
    if m is None or m.sensor != "rgbd":
        return []
    names = {b.name for b in pick.line.belts}
    points = [belt_frame(b).multiply([s, 0.0, 0.0]) for b in pick.belts if b.name in names
              for s in np.arange(-b.length / 2, b.length / 2, VIEW_STEP)]
    if np.any(in_view(camera_pose(m.camera), camera_info(m.camera), np.array(points))):
        return []
    return [f"measurement.camera: the camera at {describe_pose(m.camera)} sees none of the line's belts: "
            f"every part will be not seen"]


def line_warnings(scenario, driver=None) -> list[str]:
    """The arrival rate above the capacity, a blind camera (module docstring): the capacity is the
    min-tf model's estimate when the run's ``driver`` (a bound ``LineDriver``) is given, else the
    tasks' default tfs."""
    rate = 60.0 * sum(a.rate for a in scenario.pick.line.arrivals)
    fingers = slot_warnings(scenario, PickTaskConfig().margin)  # (obstacles: a slot beside a belt)
    if driver is not None and getattr(driver, "cycles", None) is not None:
        try:
            capacity, cycle = estimate(driver.scenario, driver.view.window_at, driver.cycles.model)
        except NoTfFits as error:
            return _blind(scenario) + fingers + [
                f"pick.line: the arm's capacity could not be estimated ({error}, at the middle of a "
                f"reach window, line.cycle.estimate); the run goes on"]
        how = (f"the feasibility model's estimate: 60 / a {cycle:.2f} s cycle at the min tfs, "
               f"line.cycle.estimate")
    else:
        cycle = cycle_time(PickTaskConfig())
        capacity, how = 60.0 / cycle, f"60 / one pick's {cycle:.2f} s cycle with the tasks' default tfs"
    if rate <= capacity:
        return _blind(scenario) + fingers
    return _blind(scenario) + fingers + [
        f"pick.line.arrivals: {rate:.1f} parts/min arrive, above the arm's capacity "
        f"{capacity:.1f} picks/min ({how}); the run goes on"]
