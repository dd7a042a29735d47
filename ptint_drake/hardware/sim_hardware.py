"""``ptint hardware``: the scenario's world alone, as the hardware a controller process drives.

The scenario is run by the one runner (``simulation.simulate``) with ``command_link.CommandLink``
in its controller slot instead of the controller (``hardware_scenario``): the plant is discrete at
the control period T (the scenario's ``controller.control_period``, 1 ms when it has none), the
link publishes the arm's status and applies the commands it receives.  The truth stays here:
metrics.json (the scenario's metrics, verdict and series, against the true objects) is written by
this side, with a ``hardware`` block: the link's URL and channels, the round-trip latency, the
messages lost, late and re-sent, the period achieved, and on a fault its reason and how the hold
went (``link_block``).
"""

from __future__ import annotations

import copy
import dataclasses
import signal
from pathlib import Path
from typing import Callable, Optional

import numpy as np
from pydrake.multibody.plant import MultibodyPlantConfig

from ptint_drake.config.errors import ScenarioError
from ptint_drake.config.schema import Scenario
from ptint_drake.hardware.camera_link import image_channel, with_receive_buffer
from ptint_drake.hardware.arm_messages import arm_messages
from ptint_drake.hardware.link import (TRACKER_CHANNEL, WSG_COMMAND_CHANNEL, WSG_STATUS_CHANNEL, Endpoint,
                                       SenderWatch, spread, url_warning)
from ptint_drake.hardware.link_record import link_series
from ptint_drake.hardware.process import scheduler_name, stop_on_signals
from ptint_drake.hardware.session import ACTIVE, SETTLED_SPEED, HardwareSession, LinkFault, LinkSettings
from ptint_drake.outputs.folder import METRICS, SERIES, save_series, staged_output, write_json_atomic
from ptint_drake.report.run_outputs import run_metrics
from ptint_drake.robot.plant import actuator_effort_limits, nominal_plant
from ptint_drake.simulation import simulate
from ptint_drake.worlds.registry import world_of

LINK_TYPE = "ptint_drake.hardware.command_link:CommandLink"
DEFAULT_PERIOD = 0.001  # s: the rate when the scenario has no control period (docs/sampled.md)


def link_period(scenario: Scenario) -> float:
    """T: the scenario's control period, else ``DEFAULT_PERIOD``."""
    return scenario.controller.control_period or DEFAULT_PERIOD


def check_link_scenario(scenario: Scenario) -> None:
    """What the LCM path does not carry yet (ScenarioError, one line): a camera that is not a
    station's rendered depth camera (a pose sensor's samples are the true pose plus noise: no
    message carries truth).  (An arm whose joints are not one actuator each is refused by
    ``run_hardware``, which has the model.)"""
    ports = world_of(scenario).link_ports(scenario)  # (a plugin world that cannot be had: one line)
    m = scenario.measurement
    if m is not None and m.estimator != "none" and (ports is None or ports.camera is None):
        raise ScenarioError(
            "measurement: a camera over LCM is supported for a station's rendered depth camera "
            "(sensor: rgbd in a world that sends its frames); this one is not: run a scenario with "
            "analytic targets"
        )


def hardware_scenario(scenario: Scenario, settings: LinkSettings) -> Scenario:
    """``scenario`` with ``CommandLink`` in the controller slot (no hold of its own: the link is
    the hold), the plant discrete at T, and the simulator unpaced: in real time the link paces
    its ticks from the first tick after the hand-shake (``realtime.TickPacer``)."""
    out = copy.copy(scenario)
    out.controller = dataclasses.replace(scenario.controller, type=LINK_TYPE, params={}, control_period=0.0)
    world = world_of(scenario)
    own = world.own_plant_step(scenario) if scenario.multibody is None else None
    if own is not None:
        if abs(settings.period - own) > 1e-12:  # the world's own plant step
            raise ScenarioError(
                f"controller.control_period: the hardware side's plant steps at the control period "
                f"({settings.period * 1e3:g} ms), the {world.name} world's at {own * 1e3:g} ms; set "
                f"multibody.time_step to the control period"
            )
    elif scenario.multibody is None:
        out.multibody = MultibodyPlantConfig(time_step=settings.period)
    else:
        step = scenario.multibody.time_step
        if step not in (0.0, settings.period):
            raise ScenarioError(
                f"multibody.time_step: the hardware side's plant steps at the control period "
                f"({settings.period * 1e3:g} ms), got {step * 1e3:g} ms"
            )
        out.multibody = copy.copy(scenario.multibody)
        out.multibody.time_step = settings.period
    # the world's own integrator (e.g. one explicit Euler step per control period), kept
    # although the slot runs unsampled here: the link is the hold
    config = world.simulator_config(scenario)
    out.simulator = copy.copy(config if config is not None else scenario.simulator)
    out.simulator.target_realtime_rate = 0.0  # real time: the link paces its ticks (``realtime.TickPacer``)
    return out


def hold_report(series: dict, t_fault: float, nq: int) -> dict:
    """How the hold after a fault at ``t_fault`` went: the largest joint speed then and at the
    end, and when every joint speed fell below ``SETTLED_SPEED`` for good."""
    t, v = series["t"], series["v"]
    after = t >= t_fault
    speed = np.abs(v[after]).max(axis=1) if np.any(after) else np.zeros(0)
    fast = np.nonzero(speed >= SETTLED_SPEED)[0]
    settled_at = None
    if speed.size and (fast.size == 0 or fast[-1] + 1 < speed.size):
        settled_at = float(t[after][fast[-1] + 1] if fast.size else t[after][0])
    return {
        "speed_at_fault": float(speed[0]) if speed.size else None,
        "speed_at_end": float(speed[-1]) if speed.size else None,
        "settled_below": SETTLED_SPEED,
        "settled_s_after_fault": None if settled_at is None else settled_at - t_fault,
        "held_until": float(t[-1]) if len(t) else None,
    }


def link_block(session: HardwareSession, settings: LinkSettings, handshake_s: Optional[float]) -> dict:
    """metrics.json's ``hardware`` block."""
    r = session.record
    periods = np.diff(r.tick_wall) if len(r.tick_wall) > 1 else []
    block = {
        "url": session.endpoint.url,
        "messages": session.messages.name,
        "status_channel": session.messages.status_channel,
        "command_channel": session.messages.command_channel,
        "mode": "lockstep" if settings.lockstep else "realtime",
        "period": settings.period,
        "realtime_rate": None if settings.lockstep else settings.realtime_rate,
        "joints": session.n,
        "command_timeout_s": settings.command_timeout,
        "silent_periods": None if settings.lockstep else settings.silent_periods,
        "sender_check": "source address" if session.watch is not None else "stamps only",
        "scheduler": scheduler_name(),
        "receive_thread_scheduler": [scheduler_name(tid) for tid in session.endpoint.threads],
        "handshake_s": handshake_s,
        "round_trip_ms": spread(r.rtt, 1e3),
        "achieved_period_ms": spread(periods, 1e3),
        "ticks": len(r.tick_time),
        "statuses_sent": r.statuses,
        "statuses_dropped": r.dropped,
        "status_resends": r.resends,
        "commands_accepted": r.accepted,
        "commands_duplicated": r.duplicates,
        "ticks_late": r.late,
        "late_run_max": r.late_run_max,
        "silent_run_max": None if settings.lockstep else session.silence.count_max,
        "ticks_skipped": None if settings.lockstep else session.pacer.skipped,
        "skipped_run_max": None if settings.lockstep else session.pacer.skipped_run_max,
        "clock_rebased": None if settings.lockstep else session.pacer.rebased,
        "status_late_max_ms": None if settings.lockstep else 1e3 * session.pacer.late_max,
        "commands_late": r.late_commands,
        "fault": r.fault,
        "fault_kind": r.fault_kind,
        "fault_time": r.fault_time,
        "stop_signal": None if r.stop_signal is None else signal.Signals(r.stop_signal).name,
        "last_command_t": r.last_command_t,
        "last_heard_t": r.last_heard_t,
    }
    ports = session.ports
    if ports is not None:
        block |= {
            "gripper_status_channel": WSG_STATUS_CHANNEL,
            "gripper_command_channel": WSG_COMMAND_CHANNEL,
            "tracker_channel": TRACKER_CHANNEL if ports.objects else None,
            "gripper_commands_taken": r.gripper_commands,
            "companions_dropped": r.companions_dropped,
        }
        if ports.camera:
            block |= {"image_channel": image_channel(ports.camera), "frames_sent": r.frames_sent}
    if not settings.lockstep and r.tick_wall:
        wall = np.asarray(r.tick_wall) - r.tick_wall[0]
        sim = (np.asarray(r.tick_time) - r.tick_time[0]) / settings.realtime_rate
        block["lateness_ms"] = spread(np.maximum(wall - sim, 0.0), 1e3)
    return block


def link_metrics(result, session: HardwareSession, settings: LinkSettings, n: int) -> dict:
    """The run's metrics with the link's: a fault is the verdict (``failed``, its reason), and
    the ``hardware`` block (``link_block``; after a fault, how the hold went)."""
    metrics, record = result.metrics, session.record
    if record.fault is not None:
        metrics["failure"] = {"time": record.fault_time, "message": record.fault}
        metrics["status"], metrics["reasons"] = "failed", [record.fault]
        metrics["reason_codes"] = [
            {"segment": None, "code": record.fault_kind.replace(" ", "_"), "message": record.fault}
        ]
    block = link_block(session, settings, session.handshake_s)
    if record.fault is not None:
        block["hold"] = hold_report(result.series, record.fault_time, n)
    metrics["hardware"] = block
    return metrics


def run_hardware(
    scenario: Scenario,
    settings: LinkSettings,
    out: Path,
    url: Optional[str] = None,
    progress=None,
    warn: Callable[[str], None] = print,
    lcm=None,
) -> dict:
    """Run ``scenario`` as hardware over LCM (module docstring) and write metrics.json and
    series.npz into ``out``; returns the metrics.  ``LinkFault`` when no controller answers
    before the simulation starts (nothing is written).  ``lcm``: a ``DrakeLcm`` to use instead of
    one of ``url`` (a ``memq://`` one shared with a drive in this process: ``in_memory``)."""
    check_link_scenario(scenario)
    plant = nominal_plant(scenario)
    n = plant.num_actuators()
    if not (plant.num_positions() == plant.num_velocities() == n):
        raise ScenarioError(
            f"robot.model: the LCM path needs one actuator per joint ({plant.num_positions()} "
            f"positions, {n} actuators)"
        )
    hw = hardware_scenario(scenario, settings)
    ports = world_of(scenario).link_ports(scenario)
    if ports is not None and ports.camera and lcm is None:  # its own frames come back on the group
        url = with_receive_buffer(url)
    endpoint = Endpoint(
        url,
        lcm=lcm,
        listen=arm_messages(settings.messages).command_channel,
        publish=arm_messages(settings.messages).status_channel,
        also=(WSG_COMMAND_CHANNEL,) if ports is not None else (),
    )
    risk = url_warning(endpoint.url)
    if risk:
        warn(risk)
    session = HardwareSession(endpoint, n, actuator_effort_limits(plant), settings)
    session.watch = SenderWatch.for_url(endpoint.url, (session.messages.command_channel, WSG_COMMAND_CHANNEL))
    session.warn = warn
    session.ports = ports
    token = ACTIVE.set(session)
    try:  # the hand-shake is the link's initialization event (``CommandLink``): the arm's start as built
        with stop_on_signals(session):
            result = simulate(hw, progress=progress, warn=warn)
    finally:
        ACTIVE.reset(token)
        if session.watch is not None:
            session.watch.close()
    run_json = run_metrics(hw, link_metrics(result, session, settings, n), figures=False)
    with staged_output(out) as stage:
        save_series(stage / SERIES, result.series | link_series(session.record))
        write_json_atomic(stage / METRICS, run_json)
    return run_json


__all__ = [
    "DEFAULT_PERIOD",
    "LINK_TYPE",
    "LinkFault",
    "LinkSettings",
    "check_link_scenario",
    "hardware_scenario",
    "link_period",
    "run_hardware",
]
