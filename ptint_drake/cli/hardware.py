"""The hardware path's commands (issue 35, docs/hardware.md): ``ptint hardware`` (the simulated
world as the hardware, ``hardware.sim_hardware``) and ``ptint drive`` (the controller alone,
``hardware.drive``), two processes over LCM; their parsers and option types."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from ptint_drake.cli.options import count, fraction, integer_in, scenario_and_out, seconds
from ptint_drake.cli.runs import progress

SET_HELP = "override a scenario field (repeatable), as for ptint run; use the same on both sides"


def add_hardware_parsers(sub) -> None:
    """``hardware`` and ``drive``."""
    _add_hardware_parser(sub)
    _add_drive_parser(sub)


def _add_hardware_parser(sub) -> None:
    """``ptint hardware``'s parser."""
    hw = sub.add_parser(
        "hardware",
        help="the simulated world as hardware over LCM (with `ptint drive`; docs/hardware.md)",
        description="Run the scenario's world alone as the hardware: a discrete plant at the control period "
        "publishing the arm's status (lcmt_iiwa_status on IIWA_STATUS) and applying the torque "
        "commands it receives (lcmt_iiwa_command on IIWA_COMMAND) from `ptint drive` (a station "
        "with a gripper adds the gripper's lcmt_schunk_wsg_status/command and its objects' motion); a "
        "fault (no command, a bad command, a second sender) holds the arm and ends the run with its "
        "reason, and so do SIGINT and SIGTERM (exit 130, 143). Writes metrics.json (the verdict, and "
        "a hardware block with the latency) and series.npz. Exit 0 ok, 1 missed or a fault, 2 bad "
        "input.",
    )
    hw.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    _add_hardware_link_options(hw)
    hw.add_argument(
        "--drop-status",
        type=fraction("--drop-status"),
        default=0.0,
        help="a test option: the fraction of status messages not sent (default 0)",
    )
    hw.add_argument("--seed", type=int, default=0, help="seed of --drop-status")
    hw.add_argument("--out", help="output folder (default out/hardware_NAME)")
    hw.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    hw.add_argument("--quiet", action="store_true", help="no progress on stderr")
    hw.set_defaults(func=cmd_hardware)


def _add_hardware_link_options(hw: argparse.ArgumentParser) -> None:
    """``ptint hardware``'s pacing, URL and timeout options."""
    hw.add_argument(
        "--lockstep",
        action="store_true",
        help="each plant step waits for its command (the accuracy mode); default: real time",
    )
    hw.add_argument(
        "--realtime-rate",
        type=seconds("--realtime-rate"),
        default=1.0,
        help="without --lockstep: simulated s per wall s (below 1 where the machine falls behind)",
    )
    hw.add_argument("--url", help="LCM URL (default: LCM_DEFAULT_URL or Drake's, host-only ttl=0)")
    hw.add_argument(
        "--command-timeout",
        type=seconds("--command-timeout"),
        default=0.25,
        help="s without a command before the arm is held (default 0.25; in real time "
        "--silent-periods decides)",
    )
    hw.add_argument(
        "--startup-timeout",
        type=seconds("--startup-timeout"),
        default=10.0,
        help="s to wait for the first command (default 10)",
    )
    hw.add_argument(
        "--silent-periods",
        type=count("--silent-periods"),
        default=5,
        help="without --lockstep: control periods in a row without a command before the arm is held "
        "(default 5; a loaded virtual machine may stall a process longer: see docs/hardware.md)",
    )
    _add_priority_option(hw, "without --lockstep: ")
    hw.add_argument(
        "--hold-time",
        type=seconds("--hold-time"),
        default=0.5,
        help="simulated s the arm is held after a fault before the run ends (default 0.5)",
    )


def _add_drive_parser(sub) -> None:
    """``ptint drive``'s parser."""
    dr = sub.add_parser(
        "drive",
        help="the controller alone over LCM, driving `ptint hardware` or a robot (docs/hardware.md)",
        description="Run the scenario's targets and controller alone: answer each lcmt_iiwa_status on "
        "IIWA_STATUS with an lcmt_iiwa_command on IIWA_COMMAND (the torques, less what the driver "
        "adds: --driver-mode; the measured positions). Writes drive.json "
        "(what was received and sent) and drive_series.npz. Exit 0 when the scenario's end was "
        "reached, 1 when the status stopped (one line), 2 bad input.",
    )
    dr.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    dr.add_argument("--url", help="LCM URL (default: LCM_DEFAULT_URL or Drake's, host-only ttl=0)")
    dr.add_argument(
        "--status-timeout",
        type=seconds("--status-timeout"),
        default=0.5,
        help="s without a status before the drive stops (default 0.5)",
    )
    dr.add_argument(
        "--startup-timeout",
        type=seconds("--startup-timeout"),
        default=10.0,
        help="s to wait for the first status (default 10)",
    )
    _add_priority_option(dr, "")
    dr.add_argument(
        "--driver-mode",
        choices=("torque", "torque-gravity", "position-torque"),
        default="torque",
        help="what the robot's driver adds to a command, which the drive takes off: torque (nothing: "
        "ptint hardware), torque-gravity (gravity compensation: KUKA FRI torque mode, Drake's "
        "SimIiwaDriver torque-only), position-torque (Drake's IiwaDriver default: inverse dynamics "
        "around the positions sent, the measured ones) (default torque; docs/hardware.md)",
    )
    dr.add_argument("--out", help="output folder (default out/drive_NAME)")
    dr.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    dr.add_argument("--quiet", action="store_true", help="accepted like the other commands")
    dr.set_defaults(func=cmd_drive)


def _add_priority_option(parser: argparse.ArgumentParser, when: str) -> None:
    """``--priority``: the loop's real-time scheduling (``hardware.priority``)."""
    from ptint_drake.hardware.process import DEFAULT_PRIORITY  # noqa: PLC0415

    parser.add_argument(
        "--priority",
        type=integer_in("--priority", 0, 99),
        default=DEFAULT_PRIORITY,
        help=f"{when}SCHED_FIFO priority of the control loop where the system permits it (root or "
        f"an rtprio limit; else a warning), 0 for the default scheduler (default {DEFAULT_PRIORITY})",
    )


def _warn(message: str) -> None:
    print(f"ptint: warning: {message}", file=sys.stderr)


def _link_settings(args: argparse.Namespace, scenario):
    """``ptint hardware``'s options as the link's settings."""
    from ptint_drake.hardware.session import LinkSettings  # noqa: PLC0415
    from ptint_drake.hardware.sim_hardware import link_period  # noqa: PLC0415

    return LinkSettings(
        period=link_period(scenario),
        duration=scenario.duration,
        lockstep=args.lockstep,
        command_timeout=args.command_timeout,
        startup_timeout=args.startup_timeout,
        hold_time=args.hold_time,
        realtime_rate=args.realtime_rate,
        drop_status=args.drop_status,
        seed=args.seed,
        priority=args.priority,
        silent_periods=args.silent_periods,
    )


def _print_link(link: dict) -> None:
    """One line: the link's mode, period, latency and lost or late messages."""
    rtt, period = link["round_trip_ms"], link["achieved_period_ms"]
    lines = [f"hardware: {link['mode']}, period {link['period'] * 1e3:g} ms, {link['ticks']} ticks"]
    if rtt:
        lines.append(f"round trip {rtt['median']:.3f} ms median, {rtt['p99']:.3f} ms p99")
    if period:
        lines.append(f"achieved period {period['median']:.3f} ms median, {period['p99']:.3f} ms p99")
    lines.append(
        f"statuses dropped {link['statuses_dropped']}, re-sent {link['status_resends']}, ticks late "
        f"{link['ticks_late']}"
    )
    print("; ".join(lines))


def _print_segments(name: str, segments: list) -> None:
    """A line per segment: its errors, or that it was not reached."""
    for i, seg in enumerate(segments):
        print(
            f"{name} segment {i}: e(tf) = {seg['e_tf_norm'] * 1e3:.4g} mm, hold max = "
            f"{seg['e_hold_max_norm'] * 1e3:.4g} mm"
            if seg.get("e_hold_max_norm") is not None
            else f"{name} segment {i}: not reached"
        )


def _print_fault(link: dict, out) -> None:
    """The fault's one-line error on stderr, with how the held arm settled."""
    hold = link.get("hold", {})
    settled = hold.get("settled_s_after_fault")
    print(
        f"ptint: error: hardware: {link['fault']}; the arm was held"
        + (
            f" (joint speeds below {hold['settled_below']} rad/s {settled:.3f} s after the fault)"
            if settled is not None
            else " (joint speeds did not settle)"
        )
        + f"; wrote {out}/",
        file=sys.stderr,
    )


def cmd_hardware(args: argparse.Namespace) -> int:
    """``ptint hardware``: the world as hardware; exit 0 ok, 1 missed or a fault."""
    from ptint_drake.hardware.session import LinkFault  # noqa: PLC0415
    from ptint_drake.hardware.sim_hardware import check_link_scenario, run_hardware  # noqa: PLC0415

    loaded, out = scenario_and_out(args, prefix="hardware_")
    scenario = loaded.scenario
    check_link_scenario(scenario)
    settings = _link_settings(args, scenario)
    try:
        metrics = run_hardware(
            scenario,
            settings,
            out,
            url=args.url,
            progress=None if args.quiet else progress(f"hardware {scenario.name}"),
            warn=_warn,
        )
    except LinkFault as exc:
        print(f"ptint: error: hardware: {exc} (nothing written)", file=sys.stderr)
        return 1
    link = metrics["hardware"]
    _print_link(link)
    if link["fault"]:
        _print_segments(scenario.name, metrics.get("segments", []))
        _print_fault(link, out)
        if link.get("stop_signal"):  # stopped by a signal: the shell's code for it, after the hold
            return 128 + int(getattr(signal, link["stop_signal"]))
        return 1
    from ptint_drake.worlds.registry import world_of  # noqa: PLC0415

    own = world_of(scenario).report(scenario, metrics, out)  # the world's own lines, as `ptint run`'s
    if own is not None:
        return own
    _print_segments(scenario.name, metrics["segments"])
    if metrics["status"] != "ok":
        print(f"{scenario.name}: {metrics['status'].upper()} ({'; '.join(metrics['reasons'])}); wrote {out}/")
        return 1
    print(f"{scenario.name}: ok (every segment meets the criteria); wrote {out}/")
    return 0


def cmd_drive(args: argparse.Namespace) -> int:
    """``ptint drive``: the controller alone; exit 0 at the scenario's end, 1 when it stopped."""
    from ptint_drake.hardware.drive import (
        DriveFault,
        DriveRecord,
        DriveSettings,
        drive_series,  # noqa: PLC0415
        drive_summary,
        run_drive,
    )
    from ptint_drake.hardware.sim_hardware import check_link_scenario, link_period  # noqa: PLC0415
    from ptint_drake.outputs.folder import save_series, staged_output, write_json_atomic  # noqa: PLC0415

    loaded, out = scenario_and_out(args, prefix="drive_")
    scenario = loaded.scenario
    check_link_scenario(scenario)
    settings = DriveSettings(
        period=link_period(scenario),
        duration=scenario.duration,
        startup_timeout=args.startup_timeout,
        status_timeout=args.status_timeout,
        priority=args.priority,
        driver_mode=args.driver_mode,
    )
    record = DriveRecord()
    fault, url = None, args.url
    try:
        url = run_drive(scenario, settings, record, url=args.url, warn=_warn)
    except DriveFault as exc:
        fault = str(exc)
    summary = drive_summary(record, settings, record.url or url or "default") | {"fault": fault}
    with staged_output(Path(out)) as stage:
        save_series(stage / "drive_series.npz", drive_series(record))
        write_json_atomic(stage / "drive.json", summary)
    if fault:
        print(f"ptint: error: drive: {fault}", file=sys.stderr)
        return 1
    compute = summary["compute_ms"]
    print(
        f"drive: answered {record.commands} statuses (t = {record.first_t:.3f} .. {record.last_t:.3f} s), "
        f"{record.repeats} repeated, {record.gaps} ticks missing; compute "
        + (f"{compute['median']:.3f} ms median, {compute['p99']:.3f} ms p99" if compute else "n/a")
        + f"; wrote {out}/"
    )
    return 0


__all__ = ["add_hardware_parsers", "cmd_drive", "cmd_hardware"]
