"""Issue 44, a decision's cost: the answers given without a solve must be the solver's own —
``robot.reachability.inverse_kinematics`` (beyond the arm's sphere of reach: None; a question asked
before: its first answer) and ``PhaseTimes.min_tf`` (a call asked again: its first answer, dropped
when the tool's start, the posture or the belt's speed differs)."""

import numpy as np
import pytest

import ptint_drake.robot.reachability as reachability
from ptint_drake.robot.plant import nominal_plant
from ptint_drake.robot.reachability import POSITION_TOLERANCE, inverse_kinematics, reach_sphere
from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.worlds.pick.feasibility import top_down
from ptint_drake.worlds.pick.phase_time import PhaseTimes

ARMS = ["line_assembly", "assembly", "curve_pose", "curve_panda", "curve_ur5e", "catch_toss_iiwa14"]


def _arm(name: str):
    scenario = load_scenario(name)
    arm = nominal_plant(scenario)
    return arm, arm.GetFrameByName(scenario.robot.end_effector), np.radians(scenario.robot.initial_q_deg)


def _solves(monkeypatch) -> list:
    """Counts the solver's calls from ``inverse_kinematics``."""
    calls = []
    solve = reachability.Solve
    monkeypatch.setattr(reachability, "Solve", lambda prog: calls.append(1) or solve(prog))
    return calls


@pytest.mark.parametrize("name", ARMS)
def test_every_posture_within_the_limits_puts_the_tool_inside_the_sphere(name):
    """2000 postures drawn within the joint limits: the tool's point is inside the sphere, so the
    sphere never refuses a point a posture reaches; the sphere is not loose beyond the arm's reach
    by more than its links' slack (the farthest drawn point is within 30 % of its radius)."""
    arm, frame, _ = _arm(name)
    centre, radius = reach_sphere(arm, frame)
    lower, upper = arm.GetPositionLowerLimits(), arm.GetPositionUpperLimits()
    lower, upper = np.where(np.isfinite(lower), lower, -np.pi), np.where(np.isfinite(upper), upper, np.pi)
    context = arm.CreateDefaultContext()
    rng = np.random.default_rng(0)
    far = 0.0
    for _ in range(2000):
        arm.SetPositions(context, rng.uniform(lower, upper))
        far = max(far, float(np.linalg.norm(frame.CalcPoseInWorld(context).translation() - centre)))
    assert far <= radius + 1e-9 and far > 0.7 * radius, (far, radius)


def test_a_point_beyond_the_sphere_is_refused_without_a_solve_and_ik_finds_none_there(monkeypatch):
    """The RV-M1 of the line: a point just beyond the sphere (its radius plus the position box's
    half-diagonal) is None with no solve; IK itself, from 20 start postures, finds no posture
    there either (the solver asked directly)."""
    arm, frame, q0 = _arm("line_assembly")
    centre, radius = reach_sphere(arm, frame)
    direction = np.array([0.6, 0.8, 0.0])
    beyond = centre + (radius + np.sqrt(3.0) * POSITION_TOLERANCE + 1e-4) * direction
    calls = _solves(monkeypatch)
    assert inverse_kinematics(arm, frame, beyond, q0) is None and not calls
    rng = np.random.default_rng(1)
    lower, upper = arm.GetPositionLowerLimits(), arm.GetPositionUpperLimits()
    assert all(reachability._solve(arm, frame, beyond, rng.uniform(lower, upper), False, None) is None
               for _ in range(20))
    calls.clear()
    inverse_kinematics(arm, frame, centre + 0.8 * radius * direction, q0)
    assert len(calls) == 1  # a point inside is solved


def test_a_question_asked_again_is_answered_as_solved_and_a_new_posture_is_solved_again(monkeypatch):
    """The same point, start posture and orientation: one solve, the same answer to the bit (a
    copy: changing it changes no later answer); the arm's posture changed (the start) or the point
    moved by a µm: solved again, each the answer of a fresh solve."""
    arm, frame, q0 = _arm("line_assembly")
    x, R = np.array([0.25, 0.05, 0.05]), top_down(0.3)
    calls = _solves(monkeypatch)
    first = inverse_kinematics(arm, frame, x, q0, R=R)
    first[0] += 1.0
    again = inverse_kinematics(arm, frame, x, q0, R=R)
    assert len(calls) == 1 and np.array_equal(again, reachability._solve(arm, frame, x, q0, False, R))
    moved_q = q0 + [0.1, 0.0, 0.0, 0.0, 0.0]
    moved = inverse_kinematics(arm, frame, x, moved_q, R=R)
    assert len(calls) == 3 and np.array_equal(moved, reachability._solve(arm, frame, x, moved_q, False, R))
    nudged = inverse_kinematics(arm, frame, x + [1e-6, 0.0, 0.0], q0, R=R)
    assert len(calls) == 5
    assert np.array_equal(nudged, reachability._solve(arm, frame, x + [1e-6, 0.0, 0.0], q0, False, R))
    assert inverse_kinematics(arm, frame, x, q0, down=True) is not None and len(calls) == 7  # (down)


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("line_assembly")


def test_min_tf_asked_again_answers_as_computed_and_a_new_belt_speed_or_posture_computes(scenario,
                                                                                          monkeypatch):
    """An approach to a part riding at 0.1 m/s: asked again (the same first guess ``last``) it is
    not computed again, gives the same tf and leaves ``last`` as the computation did; the belt at
    0.12 m/s, another start posture, another tool start or another ``last``: computed again; each
    answer equal to the model's computation with its memo emptied (its postures cached: the
    posture cache's keys leave the start posture out, as before the memo)."""
    model = PhaseTimes.of(scenario)
    computed = []
    shortest = PhaseTimes._shortest
    monkeypatch.setattr(PhaseTimes, "_shortest", lambda self, *a: computed.append(1) or shortest(self, *a))
    start, part, ride = np.array([0.2, 0.05, 0.12]), np.array([0.3, -0.05, 0.04]), np.array([0.0, 0.1, 0.0])

    def ask(m, s=start, v=ride, q=None, last=1.0):
        m.last = last
        return m.min_tf(s, part, v, 0.0, 0.75, (0.2, 0.0), q), m.last

    first = ask(model)
    n = len(computed)
    assert ask(model) == first and len(computed) == n
    model.answers.clear()
    assert ask(model) == first and len(computed) > n
    for change in ({"v": ride * 1.2}, {"q": model.q0 + 0.05}, {"s": start + [0.01, 0.0, 0.0]}, {"last": 0.7}):
        n = len(computed)
        found = ask(model, **change)
        assert len(computed) > n, change
        model.answers.clear()
        assert found == ask(model, **change), change


def test_a_fixed_target_asked_again_leaves_the_riding_guess_alone(scenario):
    """A lift (a fixed way) answered from the memo does not set ``last`` (the computation never
    does), whatever ``last`` was when it was first computed."""
    model = PhaseTimes.of(scenario)
    grasp = np.array([0.3, 0.0, 0.04])
    model.last = 0.9
    tf = model.min_tf(grasp, grasp + [0.0, 0.0, 0.05], None, 0.5)
    model.last = 0.4
    assert model.min_tf(grasp, grasp + [0.0, 0.0, 0.05], None, 0.5) == tf and model.last == 0.4


def test_the_memo_is_dropped_when_a_way_leaves_the_posture_cache(scenario, monkeypatch):
    """A way's postures evicted (the cache full) drops every memoised answer: an answer may have
    read them."""
    import ptint_drake.worlds.pick.phase_time as phase_time  # noqa: PLC0415

    monkeypatch.setattr(phase_time, "CACHE_SIZE", 1)
    model = PhaseTimes.of(scenario)
    grasp = np.array([0.3, 0.0, 0.04])
    model.min_tf(grasp, grasp + [0.0, 0.0, 0.05], None, 0.5)
    assert len(model.answers) == 1
    model.min_tf(grasp, grasp + [0.0, 0.0, 0.06], None, 0.5)
    assert len(model.answers) == 1 and len(model.postures) == 1
