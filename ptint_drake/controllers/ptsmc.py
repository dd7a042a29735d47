"""``ptsmc``: the paper's prescribed-time interceptor in the slot (model-free).

Its settings are the paper's gains, flat on the scenario's ``controller`` block
(``controller: {K, Lambda, k, …}``, ``systems.gains.ControllerGains``) plus
``implementation``: ``fused`` (one ``PrescribedTimeInterceptor``, the fast default) or
``blocks`` (the five wired blocks of paper Fig. 1).  Telemetry: the fused system logs only
its state ports and recomputes the rest afterwards; the blocks log their own ports.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Optional

from pydrake.systems.framework import OutputPort

from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, target_columns
from ptint_drake.systems.builder import AddPrescribedTimeInterceptor, InterceptorHandles
from ptint_drake.systems.gains import ControllerGains

NAME = "ptsmc"
SUMMARY = "the paper's prescribed-time sliding-mode interceptor (TBG + second-order SMC), model-free"

# Logged signals of the wired blocks: name -> (handle attribute, output port name).
_BLOCK_PORTS = {
    "x": ("kinematics", "x"), "xdot": ("kinematics", "xdot"),
    "xi": ("tbg", "xi"), "alpha": ("tbg", "alpha"),
    "e": ("surface", "e"), "edot": ("surface", "edot"), "s": ("surface", "s"),
    "s_d": ("surface", "s_d"), "s_x": ("surface", "s_x"), "sigma": ("surface", "sigma"),
    "tau": ("controller", "tau"),
}


def gains_of(block) -> ControllerGains:
    """The paper's gains of a scenario's ``controller`` block (it extends ``ControllerGains``)."""
    return ControllerGains(**{f.name: getattr(block, f.name) for f in fields(ControllerGains)})


def settings_of(block):
    """ptsmc reads the flat block itself (its gains and ``implementation``)."""
    return block


def AddPtsmc(slot: ControllerSlot, config, target: TargetView) -> ControllerHandles:
    """Add the interceptor (``config``: the scenario's flat controller block) to the slot."""
    builder = slot.builder
    fused = config.implementation == "fused"
    h = AddPrescribedTimeInterceptor(
        builder, slot.plant, slot.frame, slot.schedule,
        target.analytic if fused else None, gains_of(config),
        connect_actuation=False, fused=fused, state_port=slot.state, posture=slot.initial_q)
    system = h.fused or h.controller
    builder.Connect(system.GetOutputPort("u"), slot.actuation)
    port = None
    if h.target_input is not None:
        port = target.port()
        builder.Connect(port, h.target_input)
    notes = [f"ptsmc: K = {config.K:g}, Λ = {config.Lambda:g}, k = {config.k:g}, "
             f"{config.switching} law"]
    if fused:
        return _fused_handles(h, port, notes)
    return _block_handles(h, port, notes)


def _fused_handles(h: InterceptorHandles, target: Optional[OutputPort], notes) -> ControllerHandles:
    """The fused system logs only state ports; its telemetry is recomputed afterwards."""
    system = h.fused
    ports = {"sigma": system.GetOutputPort("sigma"), "captured": system.GetOutputPort("captured")}
    if target is not None:
        ports["target"] = target

    def telemetry(logs: dict) -> dict:
        rows = system.telemetry_at(logs["t"], logs["state"], logs["sigma"], logs["captured"],
                                   logs.get("target"))
        return {name: rows[:, part] for name, part in system.layout.items()}

    return ControllerHandles(NAME, ports, telemetry, notes, system=system)


def _block_handles(h: InterceptorHandles, target: Optional[OutputPort], notes) -> ControllerHandles:
    ports = {name: getattr(h, owner).GetOutputPort(port) for name, (owner, port) in _BLOCK_PORTS.items()}
    ports["target"] = h.targets.GetOutputPort("target") if h.target_input is None else target

    def telemetry(logs: dict) -> dict:
        out = {name: logs[name] for name in ports}
        out |= target_columns(out.pop("target"))
        return out

    return ControllerHandles(NAME, ports, telemetry, notes, system=h.controller)
