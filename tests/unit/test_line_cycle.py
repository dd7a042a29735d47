"""Issue 44: the line's phase times come from the minimum phase time model
(``worlds.pick.line.cycle`` over ``phase_time.PhaseTimes``) — a track's lead is the approach's and
the descend's min tf from the tool's point, the chosen task's tfs are ``cycle_time``'s, and the
capacity estimate is 60 / the model's cycle; an upstream part's approach ends as it enters reach;
a phase the plan splits by a via gets what both legs need."""

from pathlib import Path

import numpy as np
import pytest

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.line.arrivals import line_scenario
from ptint_drake.config.pick import MoveConfig, PickTaskConfig
from ptint_drake.worlds.pick.line.cycle import LineCycles
from ptint_drake.worlds.pick.line.scheduler import Track
from ptint_drake.worlds.pick.line.via_split import fitted, split
from ptint_drake.worlds.pick.phase_time import PhaseTimes, cycle_time
from ptint_drake.worlds.pick.route import routed_plan, tool_yaws
from ptint_drake.worlds.pick.tasks import VIA_SLOT
from ptint_drake.worlds.pick.ways import nominal, segment_target, start_error

MIRRORED = str(Path(__file__).resolve().parents[1] / "two_belt_pick_mirrored.yaml")


@pytest.fixture(scope="module")
def cycles():
    """The min-tf model of line_short's station (the expanded scenario, as the run builds it)."""
    scenario, _ = line_scenario(load_scenario("line_short"))
    return LineCycles(scenario)


def cube(s: float) -> Track:
    """A cube on line_short's belt (x = 0.25 m, +y at 0.1 m/s, top at 0.135 m), ``s`` m along it."""
    return Track(0, "cube", "conveyor", (0.25, s, 0.15), s, (0.0, 1.0, 0.0), 0.1, (1.0, 0.0, 0.0),
                 0.03, 0.0212)


def test_a_lead_is_the_models_approach_and_descend_from_the_tool(cycles):
    start, part = np.array([0.13, 0.2, 0.15]), cube(-0.1)
    lead = cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0)
    model, up, ride = cycles.model, np.array([0.0, 0.0, 0.04]), np.array([0.0, 0.1, 0.0])
    approach = model.min_tf(start, np.asarray(part.position) + up, ride, 0.0, 0.75, (0.0, 0.0))
    at = np.asarray(part.position) + ride * approach
    descend = max(model.min_tf(at + up, at, ride, 0.0, 0.75, (0.0, 0.0)), 0.012 / model.gripper_speed)
    assert lead == pytest.approx(approach + descend, rel=1e-6)
    # from farther away the lead is longer; from the same point it is the cached one
    assert cycles.lead(part, (-0.3, 0.3), 5.0, start + [0.0, 0.1, 0.0], 0.0) > lead
    assert cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0) == lead


def test_the_tasks_tfs_are_the_models_cycle_and_the_descend_ends_at_the_grasp(cycles):
    start, part = np.array([0.13, 0.2, 0.15]), cube(-0.1)
    lead = cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0)
    grasp = 5.0 + np.ceil(lead / 0.1) * 0.1
    cycle = cycles.phases(part, (-0.3, 0.3), grasp, 5.0, start, 0.0, 3)
    task = cycles.task_of("cube_0", 3, grasp, 5.0, cycle)
    assert task.start + task.approach.tf + task.descend.tf == pytest.approx(grasp)
    assert task.approach.tf >= cycle.phases["approach"] - 1e-9  # stretched to the grid, never shorter
    for phase in ("descend", "lift", "carry", "place", "retreat"):
        assert getattr(task, phase).tf == cycle.phases[phase]
    # the carry is the model's for the payload held: a heavier part gets a carry no shorter
    heavy = cycle_time(cycles.model, part.at(task.start, 5.0), np.array([0.0, 0.1, 0.0]),
                       np.array([0.13, 0.2, 0.125]), mass=2.0, start=start, yaw=0.0)
    light = cycle_time(cycles.model, part.at(task.start, 5.0), np.array([0.0, 0.1, 0.0]),
                       np.array([0.13, 0.2, 0.125]), mass=0.1, start=start, yaw=0.0)
    assert heavy.phases["carry"] >= light.phases["carry"]
    assert isinstance(cycles.model, PhaseTimes)


def test_an_upstream_parts_approach_ends_as_the_part_enters_its_reach(cycles):
    """The approach starts before the part enters its window, so that it ends as the part enters:
    the lead counts from the entry (the descend and what is left), not the whole approach."""
    start, part, window = np.array([0.13, 0.2, 0.15]), cube(-0.5), (-0.3, 0.3)
    approach, descend, wait, early, _ = cycles.found(part, window, start, 0.0)
    ahead = 2.0  # s until the part's centre is at -0.3 m at 0.1 m/s
    assert early > 0.0
    assert ahead + wait - early >= 0.0  # not before now
    assert ahead + wait - early + approach >= ahead - 1e-9  # it ends with the part in reach
    up, ride = np.array([0.0, 0.0, 0.04]), np.array([0.0, 0.1, 0.0])
    at_start = part.at(ahead + wait - early, 0.0)
    cycles.model.last = early  # the fixed point's first guess, as the lead's (a shorter way leaves reach)
    assert approach == pytest.approx(cycles.model.min_tf(start, at_start + up, ride, 0.0, 0.75, (0.0, 0.0)))
    lead = cycles.lead(part, window, 5.0, start, 0.0)
    assert lead == pytest.approx(approach + descend + wait - early)
    assert lead < approach + descend  # the old rule: the whole approach after the entry
    cycles.drop_early(part.id)  # (its cycle found no early approach): the whole approach after the entry
    assert cycles.found(part, window, start, 0.0)[3] == 0.0
    assert cycles.lead(part, window, 5.0, start, 0.0) > lead
    cycles.plain.clear()


def test_a_kept_task_fits_only_with_the_models_approach_before_its_grasp(cycles):
    start, part = np.array([0.13, 0.2, 0.15]), cube(-0.1)
    lead = cycles.lead(part, (-0.3, 0.3), 5.0, start, 0.0)
    assert cycles.fits(part, 5.0, 5.0 + lead + 0.05, 5.0, start, 0.0)
    assert not cycles.fits(part, 5.0, 5.0 + 0.5 * lead, 5.0, start, 0.0)


def _legs(world, plan, k: int, mass: float) -> list:
    """(start, target, tf, ride, payload, beta, yaws) of each via, approach and carry segment of
    task ``k`` in ``plan``, each from the previous segment's target (the plan's way)."""
    yaws, out = tool_yaws(world, plan), []
    for i, seg in enumerate(plan.segments):
        if seg.task != k or seg.phase not in ("via", "approach", "carry"):
            continue
        s = plan.schedule[i]
        target = segment_target(world, plan, i, s.start)[0]
        ride = world.parts[seg.index][1] if seg.kind == "part" else None
        payload = mass if seg.phase == "carry" or seg.kind == VIA_SLOT else 0.0
        out.append((target + start_error(world, plan, i), target, s.tf, ride, payload, s.beta, yaws[i]))
    return out


def test_a_phase_split_by_a_via_gets_what_both_legs_need():
    """two_belt_pick_mirrored on rvm1_5dof: pick 1's approach and carry each go through a via, the
    phase's tf shared by the legs by their lengths, the via's leg turning the tool.  At the
    scenario's 1.2 s a leg asks a joint for more than its limit (the model's check, ``demand``);
    split as ``via_split`` fits it to the legs' min tfs (``detours``), both legs are within the
    limits, and the phase is no longer than the length share kept would make it."""
    scenario = load_scenario(MIRRORED)
    cycles = LineCycles(scenario)
    model, mass = cycles.model, scenario.pick.parts[1].mass
    plan = routed_plan(scenario, arm=model.arm)
    needs = cycles.detours(scenario, plan, 1, mass)
    assert set(needs) == {"approach", "carry"} and cycles.detours(scenario, plan, 0, mass) == {}
    legs = _legs(nominal(scenario, model.arm), plan, 1, mass)
    assert [leg[2] for leg in legs[:2]] == pytest.approx([plan.schedule[6].tf, plan.schedule[7].tf])
    assert max(model.demand(a, b, tf, v, m, beta, y) for a, b, tf, v, m, beta, y in legs) > 1.0
    task, tfs = scenario.pick.tasks[1], []
    for phase in ("approach", "carry"):  # via, approach, via, carry
        first, second, share = needs[phase]
        move = split(getattr(task, phase), first, second, share)
        assert move is not None and move.tf <= max(first / share, second / (1.0 - share)) + 1e-9
        tfs += [move.via_share * move.tf, (1.0 - move.via_share) * move.tf]
    after = [model.demand(a, b, tf, v, m, beta, y) for (a, b, _, v, m, beta, y), tf in zip(legs, tfs)]
    assert max(after) <= 1.0 + 1e-6, after


def test_a_via_split_gives_each_leg_its_own_and_no_more():
    """``via_split.split``: an approach (its end the chosen grasp) whose share already gives both
    legs their min tfs is kept; a short one becomes tf₁ + tf₂ split tf₁ : tf₂ (the length share
    would have stretched it to tf₁ / share); one long enough in all but split wrong keeps its tf,
    its share moved the least.  A carry takes tf₁ + tf₂ even where that is shorter."""
    move = MoveConfig(2.0, 0.6)
    assert split(move, 0.9, 1.0, 0.5) is None
    short = split(move, 1.5, 1.0, 0.5)
    assert short.tf == pytest.approx(2.5) and short.via_share == pytest.approx(0.6) and short.beta == 0.6
    assert short.tf < 1.5 / 0.5
    moved = split(move, 1.2, 0.5, 0.5)
    assert moved.tf == 2.0 and moved.via_share == pytest.approx(0.6)
    carry = split(MoveConfig(3.3, 0.6), 1.5, 1.0, 0.5, fixed_end=False)
    assert carry.tf == pytest.approx(2.5) and carry.via_share == pytest.approx(0.6)
    assert split(MoveConfig(2.52, 0.6), 1.5, 1.0, 0.6, fixed_end=False) is None


def test_a_phase_whose_via_went_keeps_the_models_straight_tf():
    """``via_split.fitted``: a carry shortened for its via's legs goes back to the model's
    straight tf when a later plan has no via there (an obstacle cleared by the new timing); an
    approach stretched to its grasp is never cut, and one shorter than the model's is stretched."""
    task = PickTaskConfig(part="p", slot=0, approach=MoveConfig(2.0), carry=MoveConfig(1.0, 0.6, 0.4))
    straight = {"approach": 0.8, "carry": 1.6}
    assert fitted(task, {}, straight) == {"carry": MoveConfig(1.6, 0.6)}
    out = fitted(task, {"approach": (1.5, 1.0, 0.5)}, straight)
    assert out["approach"].tf == pytest.approx(2.5) and out["carry"].tf == 1.6
    squeezed = PickTaskConfig(part="p", slot=0, approach=MoveConfig(2.06), carry=MoveConfig(1.6))
    assert fitted(squeezed, {}, {"approach": 3.08, "carry": 1.6}) == {"approach": MoveConfig(3.08)}


def test_a_via_share_outside_0_1_is_refused():
    """A task's ``via_share`` is a fraction of the phase's tf: 0 or 1 leaves a leg no time."""
    from ptint_drake.config.errors import ScenarioError
    from ptint_drake.worlds.pick.tasks import check_tasks

    scenario = load_scenario(MIRRORED)
    scenario.pick.tasks[1].carry.via_share = 1.0
    with pytest.raises(ScenarioError, match=r"pick.tasks\[1\].carry.via_share"):
        check_tasks(scenario.pick)


def test_the_model_plans_a_held_part_at_the_arms_rated_payload_less_its_hand():
    """``cycle.held_mass``: a part's true mass is unknown on the controller side, so the min-tf
    model plans at the most the arm may carry (the RV-M1: 1.2 kg less its 0.14 kg hand), never
    below the declared mass, and at the declared mass on an arm without a rated payload."""
    from ptint_drake.simulation.scenario import LoadedScenario
    from ptint_drake.worlds.pick.line.cycle import held_mass

    scenario = LoadedScenario.load("line_short").scenario
    assert abs(held_mass(scenario, 0.1) - 1.06) < 0.01
    assert held_mass(scenario, 1.5) == 1.5
    scenario.robot.model = "not_rated"
    assert held_mass(scenario, 0.1) == 0.1


def test_an_estimate_kept_for_the_process_leaves_a_fresh_model_as_computing_it_does():
    """``cycle.estimate`` asked of a fresh model is kept for the process (a study's samples share
    the controller side's cell), and a hit leaves the model as the computation does — the postures
    it solved and the riding phases' last tf, which the run's phases start from — so a sample's
    run does not depend on what its worker ran before; another cell is computed anew."""
    from ptint_drake.worlds.pick.line import cycle

    scenario, _ = line_scenario(load_scenario("line_short"))
    window = lambda belt, lateral, height: (-0.1, 0.1)  # noqa: E731
    cycle._ESTIMATES.clear()
    computed = PhaseTimes.of(scenario)
    found = cycle.estimate(scenario, window, computed)
    kept = PhaseTimes.of(scenario)
    assert cycle.estimate(scenario, window, kept) == found and len(cycle._ESTIMATES) == 1
    assert kept.postures.keys() == computed.postures.keys() and kept.last == computed.last
    scenario.pick.belts[0].speed *= 1.2
    faster = cycle.estimate(scenario, window, PhaseTimes.of(scenario))
    assert len(cycle._ESTIMATES) == 2 and faster != found


def test_a_lead_with_no_tf_names_the_way_to_where_the_part_is_now(cycles):
    """Every wait failing, the reason is the first way's (the part where it is now), not the last
    wait's 2 s downstream (line_two_belts: 'to y = 0.379 m' named a part then at 0.18 m)."""
    cycles._leads.clear()
    why = cycles.lead(cube(0.5), (-0.3, 0.3), 5.0, np.array([0.13, 0.2, 0.15]), 0.0)
    assert isinstance(why, str) and why.startswith("no tf fits"), why
    assert why.endswith("to [0.25, 0.5, 0.19] m"), why
