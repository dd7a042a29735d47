"""``pd``: a task-space PID in the slot (model-free baseline; ``systems.pd``).

Settings under ``controller.pd`` (``systems.pd.PDConfig``: the pole-placement rule per segment,
or fixed Kp, Kd, Ki).
"""

from __future__ import annotations

from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.pd import PDConfig, PDController

NAME = "pd"
SUMMARY = "task-space PID, gains by pole placement per segment (no TBG), model-free"
CONFIG = PDConfig


def AddPd(slot: ControllerSlot, config: PDConfig, target: TargetView) -> ControllerHandles:
    """Add the PID and wire it to the slot."""
    system = slot.builder.AddNamedSystem("pd", PDController(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config))
    port = slot.connect(system, target)
    notes = []
    for i, segment in enumerate(slot.schedule.segments):
        g = config.gains_for(segment.tf)
        notes.append(f"pd segment {i}: Kp = {g['Kp']:.4g} N/m, Kd = {g['Kd']:.4g} N·s/m, "
                     f"Ki = {g['Ki']:.4g} N/(m·s) (triple pole at −{g['omega']:.3g} rad/s for "
                     f"{config.mass:g} kg)")
    return telemetry_handles(NAME, system, port, notes)
