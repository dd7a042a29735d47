"""Issue 44: an outgoing belt as a destination (line_out_belt: cubes arrive on belt ``infeed``, the
arm puts each on belt ``outfeed``, the place riding it).  From the truth (the probe's log of every
part): every cube that entered is on the outgoing belt, upright and inside its width; no two cubes
on it ever closer than the pitch that keeps the open fingers clear; no collision.  Bad outgoing
belts are one line naming the field, exit 2."""

import numpy as np
import pytest

from ptint_drake.worlds.pick.cell import world_config
from ptint_drake.worlds.pick.grasp_gate import finger_extent
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.worlds.pick.out_belt import REST_TOL, UPRIGHT_DEG, pitch
from ptint_drake.worlds.pick.probe import PART_WIDTH
from ptint_drake.worlds.pick.scene import belt_frame
from ptint_drake.worlds.pick.station import MakePickStation

# 20 s (releases over the first 14 s: the drain of the bundled 12 s would leave 8 s), about 25 CPU s;
# and with the outgoing belt at 0.02 m/s, where the cubes crowd and the pitch binds (measured: the
# last three put 40 mm apart, the pitch)
SHORT = ("duration=20", "pick.line.arrivals[0].until=6")
CASES = {"as bundled": SHORT, "a slow outgoing belt": (*SHORT, "pick.belts[1].speed=0.02")}
PLACE_TOL = 0.003  # m: the place's error along the belt (measured 0.8–1.1 mm from the riding point)


def _resting_on(belt, series, k: int, height: float) -> tuple:
    """Per sample: part k's coordinate along ``belt`` and whether it rests on it (centre h/2 above
    its top within REST_TOL, inside its width and length)."""
    world = series["probe"][:, PART_WIDTH * k: PART_WIDTH * k + 3]
    local = belt_frame(belt).inverse().multiply(world.T).T
    on = ((np.abs(local[:, 2] - height / 2) <= REST_TOL) & (np.abs(local[:, 1]) <= belt.width / 2)
          & (np.abs(local[:, 0]) <= belt.length / 2))
    return local[:, 0], on


@pytest.mark.slow
@pytest.mark.parametrize("case", sorted(CASES))
def test_every_part_that_entered_is_put_on_the_outgoing_belt_upright_and_a_pitch_apart(run, case):
    result = run("line_out_belt", CASES[case])
    m, scenario = result.metrics, result.scenario
    line, picks = m["line"], m["picks"]
    assert line["entered"] >= 4 and line["placed"] == line["entered"], line["parts"]
    assert m["status"] == "ok"
    assert all(p["destination"] == "belt outfeed" for p in line["parts"] if p["entered"])
    for pick in picks:
        assert pick["belt"] == "outfeed" and pick["slot"] is None and pick["on_belt"], pick
        assert not pick["collision"] and not pick["collision_with"], pick
    # the truth: at every sample after its retreat each placed cube rests on the outgoing belt, upright
    expanded, _ = line_scenario(scenario)  # (the pool, as the run made it)
    station = MakePickStation(world_config(expanded))
    out = next(b for b in scenario.pick.belts if b.name == "outfeed")
    cube = expanded.pick.parts[0]
    gap = pitch(cube, cube, finger_extent(station)[1])
    assert gap >= cube.size[1] + 0.005  # the pitch keeps a real gap between the cubes
    planned = np.diff(np.sort([p["belt_at"] for p in picks]))
    assert np.all(planned >= gap - 1e-6)
    if case == "a slow outgoing belt":  # the pitch, not the belt's speed, kept them apart
        assert np.min(planned) < gap + 0.002, planned
    series, t = result.series, result.series["t"]
    along = []
    for pick, grasp in zip(picks, [p["t_grasp_prescribed"] for p in picks]):
        s, on = _resting_on(out, series, pick["part_index"], cube.size[2])
        after = (t > grasp + 3.0) & (s < out.length / 2 - 0.05)  # released and not yet at the belt's end
        assert np.all(on[after]), pick["part"]
        first = PART_WIDTH * pick["part_index"] + 3
        q = series["probe"][after, first: first + 4]  # (w, x, y, z): the tilt of its vertical axis
        tilt = np.degrees(2.0 * np.arcsin(np.clip(np.hypot(q[:, 1], q[:, 2]) / np.linalg.norm(q, axis=1),
                                                  0.0, 1.0)))
        assert np.all(tilt <= UPRIGHT_DEG), pick["part"]
        along.append(np.where(on, s, np.nan))
    along = np.array(along)  # parts × samples: at every sample, the cubes on the belt a pitch apart
    for j in range(0, len(t), 25):
        s = np.sort(along[~np.isnan(along[:, j]), j])
        assert np.all(np.diff(s) >= gap - PLACE_TOL), (t[j], s)


BAD = {
    "an unknown belt": ("pick.line.catalog[0].belt=nope", "pick.line.catalog[0].belt", "no belt named"),
    "a fed belt": ("pick.line.catalog[0].belt=infeed", "pick.line.catalog[0].belt", "fed by"),
    "a belt and slots": ("pick.line.catalog[0].slots=[0]", "pick.line.catalog[0].belt", "exactly one"),
    "a belt out of reach": ("pick.belts[1].center=[0.9,0.0,0.135]", "pick.line.catalog[0].belt",
                            "within what the arm reaches"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_bad_outgoing_belt_is_one_line_naming_the_field_and_exit_2(refused_run, case):
    override, field, detail = BAD[case]
    line = refused_run("line_out_belt", override)
    assert field in line and detail in line, line
