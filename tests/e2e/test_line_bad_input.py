"""Issue 44: bad line input gets one line naming the field and exit 2, nothing written — an
unknown belt, a catalog part wider than the gripper's stroke less the margin, a slot out of reach,
a kind's slot that is not the tray's, an unknown way to fill them, an unknown kind in the mix."""

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
    "an unknown way to fill a kind's slots": ("pick.line.catalog[0].fill=nearest",
                                              "pick.line.catalog[0].fill", "not one of cycle, order"),
    "an unknown kind in the mix": ("pick.line.arrivals[0].mix={disc: 1.0}", "pick.line.arrivals[0].mix",
                                   "not a catalog kind"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_line_input_is_one_line_naming_the_field_and_exit_2(refused_run, case):
    override, field, detail = CASES[case]
    line = refused_run("line_short", override)
    # the field an override made invalid: ``--set: FIELD: …`` (simulation.scenario.LoadedScenario.parse)
    assert line.startswith(f"ptint: error: --set: {field}") and detail in line, line
