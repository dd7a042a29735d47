"""The ``orientation`` reason of the verdict (metrics.segment_reasons, metrics.verdict) on crafted
metrics: a segment of a task with orientation misses when the angle at tf is beyond
``criteria.e_rot_tf_deg`` or the angle while holding beyond ``criteria.rot_hold_deg``; an angle
that halved too soon is ``early`` (once, beside a position that did too).  A real run that misses
on orientation: tests/e2e/test_verdict.py."""

import pytest

from ptint_drake.verdict.metrics import Criteria, Reason, segment_reasons, verdict


def _seg(rot0=60.0, rot_half=30.0, rot_tf=0.5, rot_hold=1.0, **position):
    """A segment's metrics that meet the default criteria unless told otherwise (the hold's
    angle includes the one at tf, as ``rotation_metrics`` computes it)."""
    seg = {"e0_norm": 0.05, "e_half_norm": 0.025, "e_tf_norm": 1e-4, "edot_tf_norm": 0.0,
           "e_hold_max_norm": 5e-4, "e_rot0_deg": rot0, "e_rot_half_deg": rot_half,
           "e_rot_tf_deg": rot_tf, "e_rot_hold_max_deg": rot_hold, "edot_rot_tf_deg_s": 0.0}
    return seg | position


@pytest.mark.parametrize("seg, reasons", [
    (_seg(), []),
    (_seg(rot_tf=2.0, rot_hold=5.0), []),  # on both bounds: within
    (_seg(rot_tf=2.1, rot_hold=2.1), ["orientation"]),  # at tf: 2.1° > 2°
    (_seg(rot_tf=1.9, rot_hold=5.1), ["orientation"]),  # in the hold only: 5.1° > 5°
    (_seg(rot_tf=30.0, rot_hold=40.0), ["orientation"]),  # both: one reason
    (_seg(rot_half=10.0), ["early"]),  # 10° < 0.25 × 60° at tf/2
    (_seg(rot0=4.0, rot_half=0.1), []),  # starting within 5°: cannot arrive early
    (_seg(rot_half=10.0, e_half_norm=0.001), ["early"]),  # position and angle early: once
    (_seg(rot_tf=3.0, rot_hold=3.0, e_tf_norm=2e-3, e_hold_max_norm=2e-3), ["late", "orientation"]),
    (_seg(rot_tf=2.5, rot_hold=2.5, e_hold_max_norm=4e-3), ["hold", "orientation"]),
    # a position task has no angle (rotation_metrics gives None): no orientation criterion
    (_seg(rot0=None, rot_half=None, rot_tf=None, rot_hold=None), []),
])
def test_segment_reasons_with_orientation(seg, reasons):
    assert segment_reasons(seg, Criteria()) == reasons


def test_the_verdict_names_the_segment_that_missed_its_orientation():
    metrics = {"segments": [_seg(), _seg(rot_tf=2.5, rot_hold=2.5)]}
    status, reasons = verdict(metrics, Criteria())
    assert (status, reasons) == ("missed", [Reason(1, "orientation")])
    assert str(reasons[0]) == "segment 1: orientation"
    assert reasons[0].as_dict() == {"segment": 1, "code": "orientation"}
    assert Reason.from_dict(reasons[0].as_dict()) == reasons[0]


def test_the_orientation_bounds_are_the_scenario_criteria_and_the_margin_tightens_them():
    at_tf = {"segments": [_seg(rot_tf=2.5, rot_hold=2.5)]}
    assert verdict(at_tf, Criteria(e_rot_tf_deg=3.0)) == ("ok", [])
    assert verdict(at_tf, Criteria(e_rot_tf_deg=3.0), margin=2.0) == ("missed", [Reason(0, "orientation")])
    in_hold = {"segments": [_seg(rot_tf=1.0, rot_hold=6.0)]}
    assert verdict(in_hold, Criteria()) == ("missed", [Reason(0, "orientation")])
    assert verdict(in_hold, Criteria(rot_hold_deg=7.0)) == ("ok", [])
    # the angle at tf is held to e_rot_tf_deg, not to the looser rot_hold_deg
    assert verdict(at_tf, Criteria(rot_hold_deg=10.0)) == ("missed", [Reason(0, "orientation")])
