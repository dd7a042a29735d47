"""``ptsmc``: the paper's prescribed-time interceptor in the slot (model-free).

Its settings are the paper's gains, flat on the scenario's ``controller`` block
(``controller: {K, Lambda, k, …}``, ``controllers.ptsmc.gains.ControllerGains``) plus
``implementation``: ``fused`` (one ``PrescribedTimeInterceptor``, the fast default) or
``blocks`` (the five wired blocks of paper Fig. 1).  Telemetry: the fused system logs only
its state ports and recomputes the rest afterwards; the blocks log their own ports.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Optional

import numpy as np
from pydrake.systems.framework import OutputPort

from ptint_drake.controllers.ptsmc.builder import AddPrescribedTimeInterceptor, InterceptorHandles
from ptint_drake.controllers.ptsmc.gains import ControllerGains
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, target_columns
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.orientation import rotation_angle, target_rotation_values

NAME = "ptsmc"
NEAR_HALF_TURN_DEG = 170.0  # a pose segment starting further turned than this gets a warning
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
    port = rotation = None
    if h.target_input is not None:
        port = target.port()
        builder.Connect(port, h.target_input)
    if h.rotation_input is not None:  # the slot connects the orientation when the task needs it
        rotation = target.rotation_port()
        builder.Connect(rotation, h.rotation_input)
    notes = [f"ptsmc: K = {config.K:g}, Λ = {config.Lambda:g}, k = {config.k:g}, "
             f"{config.switching} law" + ("" if config.task == "position" else
                                          f", task {config.task}, rot_scale {config.rot_scale:g} m/rad")]
    notes += orientation_notes(slot, config)
    if fused:
        return _fused_handles(h, port, rotation, notes)
    return _block_handles(h, port, rotation, config.task, notes)


def orientation_notes(slot: ControllerSlot, config) -> list:
    """A warning when a ``pose`` segment starts with the tool turned nearly 180° from the object
    (the shorter rotation is then ill-defined: log(R R_rᵀ) may flip its axis)."""
    if config.task != "pose":
        return []
    kin = FrameKinematics(slot.plant, slot.frame)
    R = kin.compute_pose(slot.initial_q, np.zeros(slot.plant.num_velocities()))[2]
    notes = []
    for i, (seg, tg) in enumerate(zip(slot.schedule.segments, slot.targets)):
        angle = np.degrees(rotation_angle(R, np.reshape(target_rotation_values(tg, seg.start)[0:9], (3, 3))))
        if angle > NEAR_HALF_TURN_DEG:
            notes.append(f"ptsmc: warning: segment {i} starts {angle:.0f}° from the object's "
                         f"orientation (near 180°: the shorter rotation may flip)")
    return notes


def _fused_handles(h: InterceptorHandles, target: Optional[OutputPort], rotation: Optional[OutputPort],
                   notes) -> ControllerHandles:
    """The fused system logs only state ports; its telemetry is recomputed afterwards."""
    system = h.fused
    ports = {"sigma": system.GetOutputPort("sigma"), "captured": system.GetOutputPort("captured")}
    if target is not None:
        ports["target"] = target
    if rotation is not None:
        ports["target_rotation"] = rotation

    def telemetry(logs: dict) -> dict:
        rows = system.telemetry_at(logs["t"], logs["state"], logs["sigma"], logs["captured"],
                                   logs.get("target"), logs.get("target_rotation"))
        return {name: rows[:, part] for name, part in system.layout.items()}

    return ControllerHandles(NAME, ports, telemetry, notes, system=system)


def _block_handles(h: InterceptorHandles, target: Optional[OutputPort], rotation: Optional[OutputPort],
                   task: str, notes) -> ControllerHandles:
    ports = {name: getattr(h, owner).GetOutputPort(port) for name, (owner, port) in _BLOCK_PORTS.items()}
    ports["target"] = h.targets.GetOutputPort("target") if h.target_input is None else target
    if task != "position":
        ports["R"], ports["omega"] = h.kinematics.GetOutputPort("R"), h.kinematics.GetOutputPort("omega")
        ports["target_rotation"] = (h.targets.GetOutputPort("target_rotation") if rotation is None
                                    else rotation)

    def telemetry(logs: dict) -> dict:
        out = {name: logs[name] for name in ports}
        out |= target_columns(out.pop("target"))
        return out

    return ControllerHandles(NAME, ports, telemetry, notes, system=h.controller)
