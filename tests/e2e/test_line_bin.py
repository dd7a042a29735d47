"""Issue 44: a catalog kind goes to a bin (tests/line_bin.yaml: discs to the bin, cubes to the
tray's slots): the disc is dropped into the bin and counted "in the bin" with no mm criterion,
the cube placed in its slot within the criteria; no part goes where its kind does not."""

from pathlib import Path

import pytest

SCENARIO = str(Path(__file__).resolve().parents[1] / "line_bin.yaml")


def test_a_kind_with_a_bin_is_dropped_into_it_and_the_other_kind_placed_in_its_slot(run):
    m = run(SCENARIO).metrics
    line, picks = m["line"], m["picks"]
    assert line["entered"] == 2 and line["placed"] == 2 and m["status"] == "ok"
    kinds = {p["task"]: p["kind"] for p in line["parts"]}
    assert sorted(kinds.values()) == ["cube", "disc"]
    for k, pick in enumerate(picks):
        if kinds[k] == "disc":
            assert pick["bin"] == "bin" and pick["in_bin"] and pick["slot"] is None
        else:
            assert pick["slot"] in range(6) and pick["place_error_mm"] < 3.0


BAD = {
    "an unknown bin": ("pick.line.catalog[1].bin=nope", "pick.line.catalog[1].bin", "no bin named"),
    "a kind with slots and a bin": ("pick.line.catalog[1].slots=[0]", "pick.line.catalog[1].bin", "not both"),
    "a bin out of reach": ("pick.bins[0].center=[0.6,-0.6,0.06]", "pick.bins[0]",
                           "outside what the arm reaches"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_bin_destination_is_one_line_naming_the_field_and_exit_2(refused_run, case):
    override, field, detail = BAD[case]
    line = refused_run(SCENARIO, override)
    assert field in line and detail in line, line
