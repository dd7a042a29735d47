"""Issue 44: bad pick input gets one line naming the field and exit 2, nothing written — a part the
open fingers cannot take with its margin, a slot (a task's or not) out of the arm's reach."""

import pytest

CASES = {
    # 50 mm + the task's 12 mm margin: 62 mm, beyond the RV-M1 hand's 60 mm stroke (below it alone)
    "wider than the stroke less the margin": ("pick.parts[0].size=[0.05,0.03,0.03]", "pick.parts[0].size",
                                              "pick.tasks[0].margin"),
    "a slot no task uses, out of reach": ("pick.tray.slots=[{offset: [0.0, 0.0]}, {offset: [0.6, 0.6]}]",
                                          "pick.tray.slots[1]", "outside what the arm reaches"),
    "the task's slot out of reach": ("pick.tray.center=[0.5,0.4,0.1]", "pick.tray.slots[0]",
                                     "outside what the arm reaches"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_pick_input_is_one_line_naming_the_field_and_exit_2(refused_run, case):
    override, field, detail = CASES[case]
    line = refused_run("conveyor_pick_place", override)
    assert line.startswith(f"ptint: error: {field}") and detail in line, line
