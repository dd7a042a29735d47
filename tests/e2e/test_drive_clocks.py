"""The drive follows a driver's clock (issue 45): the lockstep pair over in-memory LCM with
every status restamped on its way to the drive (``tests/lcm_link/stamp_relay.py``) — epoch µs,
−1 before the clock runs (drake-iiwa-driver), a jump forward and one backward — runs to its end
with the plain pair's e(tf), and drive.json says what the clock did."""

from __future__ import annotations

import functools

import pytest

from lcm_link.stamp_relay import run_relayed_pair

pytestmark = pytest.mark.e2e

CURVE = "curve_b075_tf15"
SHORT = ["duration=0.6", "interceptions[0].tf=0.5", "controller.control_period=0.001",
         "multibody.time_step=0.001"]
EPOCH = 1_700_000_000_000_000  # µs: a driver stamping wall-clock time
HALF = 300_000  # µs: where the jumping clocks jump


def epoch(s: int, q: tuple, again: bool) -> int:
    return EPOCH + s


def unset_first(s: int, q: tuple, again: bool) -> int:
    return -1 if s == 0 and not again else EPOCH + s  # the hand-shake's statuses: no clock yet


def jump_forward(s: int, q: tuple, again: bool) -> int:
    return s + (3_600_000_000 if s >= HALF else 0)


def jump_back(s: int, q: tuple, again: bool) -> int:
    return 10**12 + s - (10_000_000 if s >= HALF else 0)


def plain(s: int, q: tuple, again: bool) -> int:
    return s


@functools.lru_cache(maxsize=None)
def relayed(clock):
    import tempfile
    from pathlib import Path

    from ptint_drake.hardware.session import LinkSettings
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text

    scenario = parse_with_overrides(scenario_text(CURVE)[1], SHORT, CURVE)
    out = Path(tempfile.mkdtemp(prefix="ptint_clock_"))
    return run_relayed_pair(scenario, LinkSettings(period=1e-3, duration=0.6, lockstep=True), out, clock)


@pytest.mark.slow
@pytest.mark.parametrize("clock, jumps, unset", [(epoch, 0, 0), (unset_first, 0, None),
                                                  (jump_forward, 1, 0), (jump_back, 1, 0)])
def test_drive_follows_the_driver_clock(clock, jumps, unset):
    metrics, drive = relayed(clock)
    reference, _ = relayed(plain)
    link = metrics["hardware"]
    assert link["fault"] is None and link["ticks"] == 600, link["fault"]
    assert drive["last_t"] >= 0.598 and drive["statuses_stale"] == 0
    e, e_ref = metrics["segments"][0]["e_tf_norm"], reference["segments"][0]["e_tf_norm"]
    assert abs(e - e_ref) < 1e-12, (e, e_ref)
    assert drive["clock"]["jumps"] == jumps
    if unset is None:
        assert drive["clock"]["unset_stamps"] >= 1 and drive["clock"]["origin_utime"] == EPOCH
    else:
        assert drive["clock"]["unset_stamps"] == unset
