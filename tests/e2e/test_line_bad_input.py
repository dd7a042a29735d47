"""Issue 44: bad line input gets one line naming the field and exit 2, nothing written — an
unknown belt, a catalog part wider than the gripper's stroke less the margin, a slot out of reach,
a kind's slot that is not the tray's, an unknown kind in the mix."""

import pytest

CASES = {
    "an arrival on an unknown belt": ("pick.line.arrivals[0].belt=nope", "pick.line.arrivals[0].belt",
                                      "no line belt named"),
    "a line belt the cell does not have": ("pick.line.belts[0].name=nope", "pick.line.belts[0].name",
                                           "no belt named"),
    # 50 mm + the task's 12 mm margin: 62 mm, beyond the RV-M1 hand's 60 mm stroke
    "a kind wider than the stroke less the margin": ("pick.line.catalog[0].size=[0.05,0.03,0.03]",
                                                     "pick.line.catalog[0].size", "stroke"),
    "a slot out of reach": ("pick.tray.center=[0.5,0.4,0.1]", "pick.tray.slots[0]",
                            "outside what the arm reaches"),
    "a kind's slot the tray does not have": ("pick.line.catalog[0].slots=[0,99]",
                                             "pick.line.catalog[0].slots", "tray slots"),
    "an unknown kind in the mix": ("pick.line.arrivals[0].mix={disc: 1.0}", "pick.line.arrivals[0].mix",
                                   "not a catalog kind"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_line_input_is_one_line_naming_the_field_and_exit_2(tmp_path, ptint_here, case):
    override, field, detail = CASES[case]
    out = tmp_path / "out"
    result = ptint_here("run", "line_short", "--quiet", "--no-replay", "--no-figures", "--out", out,
                        "--set", override)
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert result.returncode == 2, result.stderr
    assert len(lines) == 1 and "Traceback" not in result.stderr, result.stderr
    # the field an override made invalid: ``--set: FIELD: …`` (simulation.scenario.LoadedScenario.parse)
    assert lines[0].startswith(f"ptint: error: --set: {field}") and detail in lines[0], lines[0]
    assert not out.exists()
