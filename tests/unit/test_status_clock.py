"""The drive's clock (``hardware.status_clock``): a driver's status stamps to scenario time —
the identity for ``ptint hardware``'s stamps, epoch µs from their first stamp, −1 stamps before
the clock runs at the current time, stale statuses skipped, jumps followed by one period."""

from __future__ import annotations

from ptint_drake.hardware.status_clock import StatusClock

T = 1000  # µs: the period


def placed(stamps, period=1e-3):
    clock = StatusClock(period)
    return [clock.place(s) for s in stamps], clock


def test_ptint_hardware_stamps_are_scenario_time():
    out, clock = placed([0, 0, 0, T, 2 * T, 3 * T])
    assert out == [0, 0, 0, T, 2 * T, 3 * T] and clock.summary() == {
        "origin_utime": 0, "jumps": 0, "unset_stamps": 0}


def test_epoch_stamps_start_at_zero():
    epoch = 1_700_000_000_123_456
    out, clock = placed([epoch + k * T for k in range(4)] + [epoch + 9 * T])
    assert out == [0, T, 2 * T, 3 * T, 9 * T] and clock.origin == epoch and clock.jumps == 0


def test_unset_stamps_before_the_clock_runs():
    out, clock = placed([-1, -1, 5_000_000, 5_000_000 + T])
    assert out == [0, 0, 0, T] and clock.unset == 2 and clock.origin == 5_000_000


def test_stale_status_is_skipped_and_a_longer_step_back_is_a_jump():
    b, back = 10**12, 10_000_000
    out, clock = placed([b, b + T, b + 2 * T, b + T, b + 3 * T, b + 3 * T - back, b + 4 * T - back])
    assert out == [0, T, 2 * T, None, 3 * T, 4 * T, 5 * T] and clock.jumps == 1


def test_forward_jump_advances_one_period():
    hour = 3_600_000_000
    out, clock = placed([0, T, 2 * T + hour, 3 * T + hour, 8 * T + hour])
    assert out == [0, T, 2 * T, 3 * T, 8 * T] and clock.jumps == 1


def test_a_driver_of_a_longer_period():
    # 5 ms statuses to a drive of 1 ms: each step is time (not a jump)
    out, clock = placed([k * 5 * T for k in range(4)])
    assert out == [0, 5 * T, 10 * T, 15 * T] and clock.jumps == 0
