"""Issue 44: the minimum phase time model (``worlds.pick.phase_time``) — the shortest tf of a phase
that keeps every joint within its speed and effort limits along the whole profile."""

from pathlib import Path

import numpy as np
import pytest

from ptint_drake.config.pick import PHASES
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.feasibility import feasibility_warnings
from ptint_drake.worlds.pick.phase_time import MARGIN, NoTfFits, PhaseTimes, rounded_up, task_cycles
from ptint_drake.worlds.pick.route import TURN_DOUBT, turn_ways
from ptint_drake.worlds.pick.run import build_pick

MIN_TF_PICK = str(Path(__file__).resolve().parents[1] / "min_tf_pick.yaml")
BELT = np.array([0.0, 0.1, 0.0])  # m/s: conveyor_pick_place's belt
PLACE = np.array([0.15, 0.22, 0.115])  # m: its slot's place pose


@pytest.fixture(scope="module")
def model() -> PhaseTimes:
    return PhaseTimes.of(load_scenario("conveyor_pick_place"))


def test_a_longer_way_never_gets_a_shorter_tf(model):
    """A carry to above the slot, from farther and farther along one line; an approach to a part
    riding its belt, from farther and farther along the line from it to above the slot."""
    above = PLACE + [0.0, 0.0, 0.05]
    carries = [model.min_tf(above + d * np.array([0.6, -1.0, 0.0]) / np.hypot(0.6, 1.0), above, None, 0.1)
               for d in (0.02, 0.08, 0.16, 0.24, 0.32)]
    assert np.all(np.diff(carries) >= 0.0) and carries[-1] > 2 * carries[0], carries
    part = np.array([0.3, -0.1, 0.19])
    way = PLACE + [0.0, 0.0, 0.04] - part
    approaches = [model.min_tf(part + f * way, part, BELT) for f in (0.1, 0.3, 0.6, 1.0)]
    assert np.all(np.diff(approaches) >= 0.0) and approaches[-1] > 2 * approaches[0], approaches


def test_a_heavier_payload_never_gets_a_shorter_tf(model):
    """A lift of 5 cm off the belt with 0 … 1 kg in the hand: the torques grow with the payload."""
    grasp = np.array([0.3, 0.0, 0.15])
    lifts = [model.min_tf(grasp, grasp + [0.0, 0.0, 0.05], None, m) for m in (0.0, 0.1, 0.3, 0.6, 1.0)]
    assert np.all(np.diff(lifts) >= 0.0) and lifts[-1] > lifts[0], lifts


@pytest.mark.parametrize("phase", ["approach", "carry", "place"])
def test_the_returned_tf_fits_and_four_fifths_of_it_does_not(model, phase):
    """The feasibility check (``demand``: the profile evaluated afresh at that tf, its way included)
    passes at min_tf and fails at 0.8 × it, for a riding target and for fixed ones with a payload."""
    args = {"approach": (PLACE + [0.0, 0.0, 0.04], np.array([0.3, -0.12, 0.19]), BELT, 0.0, (0.0, 0.7)),
            "carry": (np.array([0.3, 0.0, 0.2]), PLACE + [0.0, 0.0, 0.05], None, 0.1, (0.7, 0.0)),
            "place": (PLACE + [0.0, 0.0, 0.05], PLACE, None, 0.1, (0.0, 0.0))}[phase]
    start, target, ride, payload, yaws = args
    tf = model.min_tf(start, target, ride, payload, yaws=yaws)
    assert model.demand(start, target, tf, ride, payload, yaws=yaws) <= 1.0
    assert model.demand(start, target, 0.8 * tf, ride, payload, yaws=yaws) > 1.0
    # the model's own bound: 1/MARGIN of the limit at the returned tf (a riding target within 3 %)
    assert model.demand(start, target, tf, ride, payload, yaws=yaws) == pytest.approx(1.0 / MARGIN, rel=0.03)


def test_a_near_quarter_turn_may_go_either_way_round():
    """The top-down task turns the tool to its target's branch (modulo π) nearest the tool's actual
    yaw, so a turn within ``TURN_DOUBT`` of 90° may go either way; any other turn has one way."""
    h = 0.5 * np.pi
    assert turn_ways((h, np.pi)) == [(h, np.pi), (h, 0.0)]
    assert turn_ways((h, 0.0)) == [(h, 0.0), (h, np.pi)]
    near = h - 0.9 * TURN_DOUBT
    assert turn_ways((0.0, -near)) == [(0.0, -near), (0.0, np.pi - near)]
    for turn in (0.0, 0.7, -0.7, h - 1.1 * TURN_DOUBT, -(h - 1.1 * TURN_DOUBT)):
        assert turn_ways((0.3, 0.3 + turn)) == [(0.3, 0.3 + turn)]


def test_a_near_quarter_turn_gets_the_slower_way_round(model):
    """A carry from above the belt to above the slot with the tool turned 90°: the two ways round
    ask very different things of the wrist, and the controller may take either (harsh line_assembly
    at e58b1cd: first carries planned +90°, the wrist's roll 5°, were turned −90° in 5 of 12 samples,
    the roll 176° at 4.3–5.1 rad/s against its 4).  Its tf is at least each way's own, one way
    turned 76.5° each way round (outside the doubt: one way each), and the same however the
    target's branch is written."""
    start, target, h = np.array([0.3, -0.05, 0.2]), PLACE + [0.0, 0.0, 0.05], 0.5 * np.pi
    one_way = [model.min_tf(start, target, None, 0.1, yaws=(h, h + s * 0.85 * h)) for s in (1.0, -1.0)]
    assert max(one_way) > 1.3 * min(one_way), one_way  # (the ways differ: 1.28 s and 1.95 s)
    either = model.min_tf(start, target, None, 0.1, yaws=(h, np.pi))
    assert either >= max(one_way) and either == model.min_tf(start, target, None, 0.1, yaws=(h, 0.0))
    assert model.demand(start, target, either, None, 0.1, yaws=(h, np.pi)) <= 1.0
    assert model.demand(start, target, 0.8 * either, None, 0.1, yaws=(h, np.pi)) > 1.0


def test_no_posture_along_the_way_is_named(model):
    with pytest.raises(NoTfFits, match="no top-down posture"):
        model.min_tf(PLACE, np.array([1.5, 0.0, 0.2]))


def test_the_scenario_runs_the_model_tfs_unwarned_and_seven_tenths_of_them_are_warned():
    """tests/min_tf_pick.yaml (assembly_pick_place's cell) carries the model's tfs, rounded up to
    10 ms: no warning before its run; at 0.7 × them every task is warned (the descend aside: its
    floor is the fingers' close)."""
    scenario = load_scenario(MIN_TF_PICK)
    cycles = task_cycles(scenario)
    for task, cycle in zip(scenario.pick.tasks, cycles):  # rounded up (1 ms either side: other Drakes)
        for phase, tf in cycle.phases.items():
            assert tf - 0.001 <= getattr(task, phase).tf <= rounded_up(tf) + 0.001, (phase, tf)
    assert feasibility_warnings(scenario, build_pick(scenario)) == []
    for task in scenario.pick.tasks:
        for phase in PHASES:
            getattr(task, phase).tf *= 0.7
    warned = feasibility_warnings(scenario, build_pick(scenario))
    for k in range(len(scenario.pick.tasks)):
        for phase in ("approach", "lift", "carry", "place", "retreat"):
            assert any(w.startswith(f"pick.tasks[{k}].{phase}.tf") for w in warned), (k, phase)
