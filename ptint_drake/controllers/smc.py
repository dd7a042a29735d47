"""``smc``: a first-order sliding mode in the slot (model-free baseline; ``systems.smc``).

It shares the paper's gains K and Λ (flat on ``controller``) and takes its own surface slope
under ``controller.smc``: a constant λ = ``lambda_factor`` / tf per segment (no TBG).
"""

# no postponed annotations here: Drake's yaml_load_typed / yaml_dump_typed read SmcOptions' types

from ptint_drake.config.controller import SmcOptions
from ptint_drake.controllers.ptsmc import gains_of
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.smc import FirstOrderSMC, SMCConfig

NAME = "smc"
SUMMARY = "first-order sliding mode with a constant slope λ = lambda_factor/tf (no TBG), model-free"


CONFIG = SmcOptions


def settings_of(block) -> SMCConfig:
    """The system's configuration: the paper's gains of ``block`` and its ``smc`` options."""
    return SMCConfig.from_gains(gains_of(block), lambda_factor=block.smc.lambda_factor)


def AddSmc(slot: ControllerSlot, config: SMCConfig, target: TargetView) -> ControllerHandles:
    """Add the first-order SMC and wire it to the slot."""
    system = slot.builder.AddNamedSystem("smc", FirstOrderSMC(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config))
    port = slot.connect(system, target)
    notes = [f"smc segment {i}: λ = {config.lambda_factor:g}/tf = {config.lambda_factor / s.tf:.3g} 1/s, "
             f"K = {config.K:g}, Λ = {config.Lambda:g}" for i, s in enumerate(slot.schedule.segments)]
    return telemetry_handles(NAME, system, port, notes)
