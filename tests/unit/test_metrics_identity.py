"""scripts/metrics_identity.py: the comparison of two metrics.json trees, and a bad argument."""

import math
import subprocess
import sys
from pathlib import Path

from script_module import load_script

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "metrics_identity.py"
identity = load_script("metrics_identity")  # (registered in sys.modules: its dataclasses look it up)


def metrics(**sim):
    return {"segments": [{"e_tf_norm": 7.085e-05, "ok": True}], "status": "ok",
            "sim": {"steps": 1409, "wall_time_s": 0.89, "realtime_factor": 3.37} | sim}


def test_identical_trees_have_no_difference():
    assert identity.compare(metrics(), metrics()) == []


def test_a_differing_number_is_reported_with_both_values_and_its_relative_difference():
    head = metrics()
    head["segments"][0]["e_tf_norm"] = 7.086e-05
    (diff,) = identity.compare(metrics(), head)
    assert diff["path"] == "segments[0].e_tf_norm"
    assert (diff["kind"], diff["base"], diff["head"]) == ("value", 7.085e-05, 7.086e-05)
    assert math.isclose(diff["rel_diff"], 1e-8 / 7.086e-05)
    assert identity.max_relative_difference([diff]) == diff["rel_diff"]


def test_a_difference_in_the_last_bit_counts():
    head = metrics()
    head["segments"][0]["e_tf_norm"] = math.nextafter(7.085e-05, 1.0)
    assert [d["path"] for d in identity.compare(metrics(), head)] == ["segments[0].e_tf_norm"]


def test_nan_equals_nan_but_not_a_number():
    assert identity.compare({"x": math.nan}, {"x": math.nan}) == []
    (diff,) = identity.compare({"x": math.nan}, {"x": 1.0})
    assert diff["path"] == "x" and diff["rel_diff"] == math.inf


def test_timing_values_are_ignored_in_the_sim_block_only():
    assert identity.compare(metrics(), metrics(wall_time_s=12.5, realtime_factor=0.24)) == []
    assert [d["path"] for d in identity.compare(metrics(), metrics(steps=1410))] == ["sim.steps"]
    # a field of the same name elsewhere is compared
    elsewhere = identity.compare({"wall_time_s": 1.0}, {"wall_time_s": 2.0})
    assert [d["path"] for d in elsewhere] == ["wall_time_s"]


def test_a_missing_key_is_reported_on_the_side_that_lacks_it():
    head = metrics()
    del head["status"]
    head["segments"][0]["new"] = 1
    diffs = {d["path"]: d["kind"] for d in identity.compare(metrics(), head)}
    assert diffs == {"status": "missing_in_head", "segments[0].new": "missing_in_base"}
    # an ignored timing field missing on one side is a difference too (only its value is ignored)
    head = metrics()
    del head["sim"]["wall_time_s"]
    assert [d["kind"] for d in identity.compare(metrics(), head)] == ["missing_in_head"]


def test_type_and_length_changes():
    kinds = [d["kind"] for d in identity.compare({"a": 1, "b": [1, 2], "c": True},
                                                 {"a": 1.0, "b": [1], "c": 1})]
    assert kinds == ["type", "length", "type"]


def test_a_bad_argument_is_one_line_naming_it():
    out = subprocess.run([sys.executable, str(SCRIPT), "--jobs", "0"], capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2
    assert out.stderr.strip().splitlines() == ["metrics_identity: error: argument --jobs: 0 is not >= 1"]
    assert out.stdout == ""
    out = subprocess.run([sys.executable, str(SCRIPT), "--base", "no-such-rev"], capture_output=True,
                         text=True, timeout=60)
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "argument --base" in out.stderr


def test_values_identical_allows_additions_only():
    """A new key, warning lines added around the base's (in their order) and a grown count of them
    are additions; a changed value, a base line dropped or reordered, a key the head lacks are not."""
    base = {"e": 1.0, "warnings": ["a", "b"], "warnings_before_run": 1}
    head = {"e": 1.0, "warnings": ["new", "a", "b", "later"], "warnings_before_run": 2, "added": 3}
    assert identity.additions_only(identity.compare(base, head), base, head)
    for change in ({"e": 1.0000000000000002},
                   {"warnings": ["b", "a"]}, {"warnings": ["a"]}, {"warnings_before_run": 0}):
        other = head | change
        assert not identity.additions_only(identity.compare(base, other), base, other), change
    lacking = {"warnings": ["a", "b"]}  # e and the count gone from the head
    assert not identity.additions_only(identity.compare(base, lacking), base, lacking)
