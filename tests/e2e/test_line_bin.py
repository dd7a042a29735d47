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
def test_a_bad_bin_destination_is_one_line_naming_the_field_and_exit_2(tmp_path, ptint_here, case):
    override, field, detail = BAD[case]
    out = tmp_path / "out"
    result = ptint_here("run", SCENARIO, "--quiet", "--no-replay", "--no-figures", "--out", out,
                        "--set", override)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 2 and len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    assert field in lines[0] and detail in lines[0], lines[0]
    assert not out.exists()
