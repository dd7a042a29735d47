"""The hardware link's checks in one process over an in-memory LCM (``memq://``): what the
two-process tests (tests/e2e/test_lcm_two_processes.py) exercise across a private namespace, here
without any network, so they run wherever a namespace cannot be made."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.lcm import DrakeLcm

from ptint_drake.hardware.link import (COMMAND_CHANNEL, STATUS_CHANNEL, Endpoint, pack_command, pack_status,
                                       unpack_command, unpack_status, url_warning, utime_of)
from ptint_drake.hardware.session import HardwareSession, LinkSettings

N = 3
LIMITS = np.array([5.0, 12.0, 12.0])


def pair(**settings):
    """(hardware session, drive endpoint) on one memq:// LCM."""
    lcm = DrakeLcm("memq://")
    hardware = Endpoint(None, listen=COMMAND_CHANNEL, publish=STATUS_CHANNEL, lcm=lcm)
    drive = Endpoint(None, listen=STATUS_CHANNEL, publish=COMMAND_CHANNEL, lcm=lcm)
    s = LinkSettings(period=1e-3, duration=1.0, command_timeout=0.05, **settings)
    return HardwareSession(hardware, N, LIMITS, s), drive


def tick(session, t, commands=()):
    """Publish ``commands`` (utime, τ bytes), then the tick at ``t``."""
    for data in commands:
        session.endpoint.lcm.Publish(COMMAND_CHANNEL, data)
    return session.exchange(t, np.zeros(N), np.zeros(N), np.zeros(N))


def test_messages_round_trip():
    q, v, tau = np.array([0.1, 0.2, 0.3]), np.array([1.0, 2.0, 3.0]), np.array([4.0, 5.0, 6.0])
    utime, q2, v2 = unpack_status(pack_status(0.0125, q, v, tau), N)
    assert utime == 12500 and np.array_equal(q, q2) and np.array_equal(v, v2)
    assert unpack_command(pack_command(7, tau), N)[0] == 7
    with pytest.raises(ValueError, match="4 torques, the arm has 3"):
        unpack_command(pack_command(7, np.zeros(4)), N)
    with pytest.raises(ValueError, match="5 joints, the scenario's arm has 3"):
        unpack_status(pack_status(0.0, np.zeros(5), np.zeros(5), np.zeros(5)), N)


def test_url_warning_names_the_risk():
    assert url_warning("udpm://239.255.76.67:7667?ttl=0") is None
    assert url_warning("memq://") is None
    for url in ("udpm://239.255.76.67:7667?ttl=1", "udpm://239.255.76.67:7667"):
        assert "anyone on that network" in url_warning(url)


def test_the_answered_command_is_taken():
    session, _ = pair()
    tau = np.array([0.5, -1.0, 2.0])
    assert np.array_equal(tick(session, 0.002, [pack_command(utime_of(0.002), tau)]), tau)
    assert session.record.fault is None and session.record.accepted == 1


@pytest.mark.parametrize(
    "tau, words",
    [
        (np.array([np.nan, 0.0, 0.0]), "non-finite torque"),
        (np.array([0.0, 12.5, 0.0]), "joint 1 torque 12.5 N·m beyond its limit 12"),
        (np.zeros(4), "4 torques, the arm has 3"),
    ],
)
def test_bad_commands_are_faults(tau, words):
    session, _ = pair()
    assert tick(session, 0.002, [pack_command(utime_of(0.002), tau)]) is None
    assert session.record.fault_kind == "bad command" and words in session.record.fault


def test_no_command_is_a_timeout():
    session, _ = pair()
    assert tick(session, 0.003) is None
    assert session.record.fault == "command timeout at t = 0.003 s (no command for 50 ms)"


@pytest.mark.parametrize(
    "second, words",
    [
        (
            lambda: pack_command(utime_of(0.004), np.ones(N)),
            "two different commands",
        ),  # same stamp, other torque
        (lambda: pack_command(utime_of(0.001), np.zeros(N)), "went backwards"),
        (lambda: pack_command(utime_of(0.5), np.zeros(N)), "no status asked for"),
    ],
)
def test_a_second_sender_is_a_fault(second, words):
    session, _ = pair()
    tick(session, 0.003, [pack_command(utime_of(0.003), np.zeros(N))])
    tick(session, 0.004, [pack_command(utime_of(0.004), np.zeros(N))])
    assert session.record.fault is None
    tick(session, 0.005, [second()])
    assert session.record.fault_kind == "second sender" and words in session.record.fault


def test_a_repeated_answer_is_no_fault():
    session, _ = pair()
    tau = np.ones(N)
    tick(session, 0.003, [pack_command(utime_of(0.003), tau)])
    out = tick(session, 0.004, [pack_command(utime_of(0.003), tau), pack_command(utime_of(0.004), tau)])
    assert session.record.fault is None and session.record.duplicates == 1 and np.array_equal(out, tau)


def test_realtime_late_ticks_then_timeout():
    """Real time: a silent controller is held after ``silent_periods`` ticks without a command
    (5 by default: 5 ms at 1 kHz, where the old rule kept the last torque for 50-250 ms)."""
    session, _ = pair(lockstep=False)
    for k in range(1, 100):  # each tick waits 0.8 ms for its command, then keeps the last torque
        tick(session, k * 1e-3)
        if session.record.fault:
            break
    assert session.record.late == k == 5 and session.record.fault_kind == "command timeout"
    assert session.record.late_run_max == 5 and "5 periods" in session.record.fault


def test_realtime_a_late_tick_between_answers_is_no_fault():
    """Four ticks in a row without a command, then one answered: the run goes on (late ticks
    counted, the longest run of them recorded), and the count starts again."""
    session, _ = pair(lockstep=False, silent_periods=5)
    t = 0.0
    for _ in range(3):
        for _ in range(4):
            t += 1e-3
            tick(session, t)
        t += 1e-3
        assert np.array_equal(tick(session, t, [pack_command(utime_of(t), np.ones(N))]), np.ones(N))
    assert session.record.fault is None and session.record.late == 12 and session.record.late_run_max == 4


@pytest.mark.parametrize("lockstep", [True, False])
def test_a_stop_signal_is_a_fault_held_like_the_others(lockstep):
    """SIGTERM / SIGINT (``request_stop``): the next tick is the fault ``stopped``, naming the
    signal and the time; no status is published for it."""
    import signal  # noqa: PLC0415

    session, _ = pair(lockstep=lockstep)
    tick(session, 0.001, [pack_command(utime_of(0.001), np.ones(N))])
    sent = session.record.statuses
    session.request_stop(signal.SIGTERM)
    assert tick(session, 0.002) is None
    assert session.record.fault_kind == "stopped" and session.record.stop_signal == signal.SIGTERM
    assert session.record.fault == "stopped by SIGTERM at t = 0.002 s" and session.record.statuses == sent


@pytest.mark.parametrize(
    "args, words",
    [
        (("hardware", "curve_camera"), "measurement: a camera over LCM"),
        (("hardware", "curve_b075_tf15", "--drop-status", "1.5"), "--drop-status: must be in [0, 1)"),
        (("drive", "curve_b075_tf15", "--status-timeout", "0"), "--status-timeout: must be > 0"),
        (
            (
                "hardware",
                "curve_b075_tf15",
                "--set",
                "multibody.time_step=0.001",
                "--set",
                "controller.control_period=0.002",
            ),
            "multibody.time_step: the hardware",
        ),
    ],
)
def test_bad_input_is_one_line(ptint_here, args, words, tmp_path):
    """Bad input: exit 2, one line naming the field, nothing written, no LCM traffic."""
    out = ptint_here(*args, "--out", tmp_path / "out")
    assert out.returncode == 2 and words in out.stderr, out.stderr
    assert len(out.stderr.strip().splitlines()) == 1 and not (tmp_path / "out").exists()


def pick_pair():
    """A hardware session of a station with a gripper (1 object, a 30 N gripper: the pick world's
    ``link_ports``) and the drive's endpoint."""
    from ptint_drake.hardware.link import WSG_COMMAND_CHANNEL  # noqa: PLC0415
    from ptint_drake.worlds.base import LinkPorts  # noqa: PLC0415

    lcm = DrakeLcm("memq://")
    hardware = Endpoint(None, listen=COMMAND_CHANNEL, publish=STATUS_CHANNEL, lcm=lcm,
                        also=(WSG_COMMAND_CHANNEL,))
    settings = LinkSettings(period=1e-3, duration=1.0, command_timeout=0.05)
    session = HardwareSession(hardware, N, LIMITS, settings)
    session.ports = LinkPorts(gripper_max_force=30.0, objects=1)
    return session, lcm


def pick_tick(session, lcm, t, gripper=()):
    """Publish the arm's command for ``t`` after the gripper commands ``gripper``, then the tick."""
    from ptint_drake.hardware.link import WSG_COMMAND_CHANNEL  # noqa: PLC0415

    for data in gripper:
        lcm.Publish(WSG_COMMAND_CHANNEL, data)
    lcm.Publish(COMMAND_CHANNEL, pack_command(utime_of(t), np.zeros(N)))
    extras = (np.zeros(4), np.zeros(2), np.zeros(18), None)  # fingers, drive forces, tracker, no frame
    return session.exchange(t, np.zeros(N), np.zeros(N), np.zeros(N), extras)


def test_the_gripper_command_for_the_next_tick_is_taken():
    from ptint_drake.hardware.link import pack_wsg_command  # noqa: PLC0415

    session, lcm = pick_pair()
    pick_tick(session, lcm, 0.002, [pack_wsg_command(utime_of(0.003), 0.042, 30.0)])
    assert session.record.fault is None and session.gripper_opening(utime_of(0.003)) == 0.042


@pytest.mark.parametrize(
    "opening, force, words",
    [(np.nan, 30.0, "not finite"), (0.042, 45.0, "force 45 N outside [0, 30] N"), (0.042, -1.0, "outside")],
)
def test_bad_gripper_commands_are_faults(opening, force, words):
    from ptint_drake.hardware.link import pack_wsg_command  # noqa: PLC0415

    session, lcm = pick_pair()
    pick_tick(session, lcm, 0.002, [pack_wsg_command(utime_of(0.003), opening, force)])
    assert session.record.fault_kind == "bad command" and words in session.record.fault


def test_two_gripper_commands_for_one_tick_are_a_second_sender():
    from ptint_drake.hardware.link import pack_wsg_command  # noqa: PLC0415

    session, lcm = pick_pair()
    two = [pack_wsg_command(utime_of(0.003), 0.042, 30.0), pack_wsg_command(utime_of(0.003), 0.0, 30.0)]
    pick_tick(session, lcm, 0.002, two)
    assert session.record.fault_kind == "second sender"
    assert "two different gripper commands" in session.record.fault


def test_gripper_status_round_trip_keeps_what_the_observer_reads():
    """The WSG status carries the opening, the faster finger's speed and the smaller squeeze;
    unpacked, the grasp observer's rule reads the same three numbers."""
    from ptint_drake.hardware.link import pack_wsg_status, unpack_wsg_status  # noqa: PLC0415

    fingers, force = np.array([0.0148, 0.0151, -0.002, 0.003]), np.array([-29.5, -30.0])
    utime, f, d = unpack_wsg_status(pack_wsg_status(0.5, fingers, force))
    assert utime == 500000
    assert abs((f[0] + f[1]) - (fingers[0] + fingers[1])) < 1e-15
    assert abs(max(abs(f[2]), abs(f[3])) - 0.003) < 1e-15 and min(-d[0], -d[1]) == 29.5
