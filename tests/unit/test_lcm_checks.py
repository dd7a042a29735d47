"""The hardware link's checks in one process over an in-memory LCM (``memq://``): what the
two-process tests (tests/e2e/test_lcm_two_processes.py) exercise across a private namespace, here
without any network, so they run wherever a namespace cannot be made."""

from __future__ import annotations

import numpy as np
import pytest
from pydrake.lcm import DrakeLcm

from ptint_drake.hardware.link import (COMMAND_CHANNEL, STATUS_CHANNEL, Endpoint, pack_command, pack_status,
                                       unpack_command, unpack_status, url_warning, utime_of)
from ptint_drake.hardware.realtime import Silence, TickPacer
from ptint_drake.hardware.session import HardwareSession, LinkSettings

N = 3
LIMITS = np.array([5.0, 12.0, 12.0])


class Wall:
    """A real-time pacer's wall clock (s) set by the test (``tick``): the test thread's own
    stalls on a loaded machine are then no stalls of the hardware."""

    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def sleep(self, s: float) -> None:
        self.now += s


def pair(**settings):
    """(hardware session, drive endpoint) on one memq:// LCM; in real time the session's pacer
    reads ``session.wall`` (``Wall``)."""
    lcm = DrakeLcm("memq://")
    hardware = Endpoint(None, listen=COMMAND_CHANNEL, publish=STATUS_CHANNEL, lcm=lcm)
    drive = Endpoint(None, listen=STATUS_CHANNEL, publish=COMMAND_CHANNEL, lcm=lcm)
    s = LinkSettings(period=1e-3, duration=1.0, command_timeout=0.05, **settings)
    session = HardwareSession(hardware, N, LIMITS, s)
    session.wall = Wall()
    session.pacer = TickPacer(s.period, s.realtime_rate, clock=session.wall, sleep=session.wall.sleep)
    return session, drive


def tick(session, t, commands=(), wall=None):
    """Publish ``commands`` (utime, τ bytes), then the tick at ``t``, found by the pacer at wall
    time ``wall`` (default: ``t``, on time)."""
    for data in commands:
        session.endpoint.lcm.Publish(COMMAND_CHANNEL, data)
    session.wall.now = t if wall is None else wall
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
    assert session.record.late_run_max == 5 and "no command for 5 statuses in a row" in session.record.fault


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


def test_silence_is_counted_in_statuses_and_a_sign_of_life_resets_it():
    """``Silence``: a status without any command counts one; a command (its own answer, or a late
    answer to an older status) sets the count back; the 5th status in a row without one is the
    hold, not the 4th."""
    silence = Silence(5)
    for heard in (False, False, False, False, True, False, False, False, False):
        silence.start_tick()
        if heard:
            silence.heard()
        assert not silence.end_tick(answered=False)
    assert silence.count == 4 and silence.count_max == 4
    silence.start_tick()
    assert silence.end_tick(answered=False) and silence.count == 5


def test_pacer_skips_the_ticks_of_its_own_stall_then_paces_again():
    """``TickPacer``: on time, each tick sleeps until it is due; after a stall of the hardware's
    own process (8.5 periods), the ticks it passed go without a status until it is within a
    period again (a plant step takes 0.1 period here) — no burst of catch-up statuses — and the
    next ones are due one period apart again."""
    wall = Wall()
    pacer = TickPacer(1e-3, 1.0, clock=wall, sleep=wall.sleep)
    for k in range(10):
        wall.now = max(wall.now, k * 1e-3 - 0.3e-3)  # each tick found a little early: it sleeps
        assert pacer.admit(k * 1e-3) and abs(wall.now - k * 1e-3) < 1e-12
    wall.now = 18.5e-3  # the tick of 10 ms found 8.5 ms late
    admitted = []
    for k in range(10, 30):
        admitted.append(pacer.admit(k * 1e-3))
        wall.now = max(wall.now, k * 1e-3) + 0.1e-3
    assert admitted == [False] * 9 + [True] * 11, admitted
    assert pacer.skipped == pacer.skipped_run_max == 9 and pacer.rebased == 0 and pacer.late_max < 1e-3


def test_pacer_goes_on_when_the_simulation_is_slower_than_real_time():
    """A plant step that takes 1.5 periods: a skipped tick does not shrink the lag, so the clock
    is set back and the tick goes out — the link never stops publishing."""
    wall = Wall()
    pacer = TickPacer(1e-3, 1.0, clock=wall, sleep=wall.sleep)
    admitted = []
    for k in range(40):
        admitted.append(pacer.admit(k * 1e-3))
        wall.now += 1.5e-3
    assert pacer.rebased > 0 and pacer.skipped_run_max <= 2 and sum(admitted) > 40 // 3


def test_a_stall_of_the_hardware_is_not_the_controller_silent():
    """Real time: the hardware's own process stalls for 30 periods while the controller answers
    every status it gets: the ticks it passed publish nothing, nothing counts as silence, the
    run goes on (the old wall-clock rule: 5 late ticks, a hold) — and a controller that then
    goes silent is held at its 5th unanswered status, 5 periods after it was last heard."""
    session, drive = pair(lockstep=False, budget=50.0)  # a tick waits 50 ms: this thread may stall
    alive, lcm = [True], session.endpoint.lcm

    def respond(data):  # the controller: each status answered as soon as it is handled
        utime = unpack_status(bytes(data), N)[0]
        if alive[0]:
            lcm.Publish(COMMAND_CHANNEL, pack_command(utime, np.full(N, utime / 1e5)))  # τ: tick (ms) / 100

    lcm.Subscribe(STATUS_CHANNEL, respond)
    for k in range(1, 11):
        assert np.array_equal(tick(session, k * 1e-3), np.full(N, k / 100))
    tick(session, 11e-3, wall=11e-3 + 30e-3)  # the hardware comes back 30 ms late at the tick of 11 ms
    for k in range(12, 60):
        tick(session, k * 1e-3, wall=session.wall.now + 0.2e-3)  # a plant step (0.2 ms) per tick
    statuses = [unpack_status(data, N)[0] for _, data in drive.poll(0.0)]
    skipped = session.pacer.skipped
    assert session.record.fault is None and session.silence.count_max == 0 and skipped >= 30, skipped
    assert session.record.late == 0 and len(statuses) == 59 - skipped  # a skipped tick sends no status
    assert not set(range(11000, 11000 + 1000 * skipped, 1000)) & set(statuses)
    alive[0], t = False, 60e-3  # the controller goes silent
    while session.record.fault is None:
        tick(session, t, wall=session.wall.now + 0.2e-3)
        t += 1e-3
    assert session.record.fault_kind == "command timeout" and "5 statuses in a row" in session.record.fault
    assert abs(session.record.fault_time - session.record.last_heard_t - 5e-3) < 1e-12


def test_a_late_answer_is_taken_and_is_a_sign_of_life():
    """Real time: a controller one status behind (each tick's wait brings the answer to the
    previous status) is alive: never held, and its newest torque steers the arm, one period
    late, instead of the first torque staying for good."""
    session, _ = pair(lockstep=False)
    assert tick(session, 1e-3) is None  # the first status's answer comes during the second's wait
    for k in range(2, 30):
        late = pack_command(utime_of((k - 1) * 1e-3), np.full(N, (k - 1) / 10))
        assert np.array_equal(tick(session, k * 1e-3, [late]), np.full(N, (k - 1) / 10))
    record = session.record
    assert record.fault is None and record.late == 29 and record.late_run_max == 29
    assert session.silence.count_max == 1 and record.late_commands == 28 and record.last_heard_t == 29e-3


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
