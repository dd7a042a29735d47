"""``ct_quintic``: a quintic joint plan tracked by inverse dynamics (model-based reference).

It uses the *nominal* model (the model file without the scenario's plant deviations) and, for
analytic targets, their exact future (``systems.ct_quintic``).  Settings under
``controller.ct_quintic`` (``CtQuinticConfig``).
"""

from __future__ import annotations

from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.ct_quintic import CtQuinticConfig, CtQuinticController
from ptint_drake.systems.signals import TARGET

NAME = "ct_quintic"
SUMMARY = ("quintic joint plan to the target's future, tracked by inverse dynamics of the nominal "
           "model (model-based)")
CONFIG = CtQuinticConfig
MODEL_BASED = True


def AddCtQuintic(slot: ControllerSlot, config: CtQuinticConfig, target: TargetView) -> ControllerHandles:
    """Add the planner + inverse-dynamics tracker and wire it to the slot."""
    predict = None
    if target.analytic is not None:
        seen = target.analytic

        def predict(i, t1, _target, seen=seen):
            values = seen[i].evaluate(t1)
            return values[TARGET.x.start:TARGET.xdot.stop]
    system = slot.builder.AddNamedSystem("ct_quintic", CtQuinticController(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config,
        nominal_plant=slot.nominal_plant(), predict=predict))
    port = slot.connect(system, target)
    notes = [f"ct_quintic: inverse dynamics of the nominal model, ω = {config.omega:g} rad/s, "
             f"target future {'exact (analytic)' if predict else 'extrapolated from the estimate'}"]
    return telemetry_handles(NAME, system, port, notes)  # model-based: MODEL_BASED, read by the registry
