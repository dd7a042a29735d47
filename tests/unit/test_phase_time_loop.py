"""Issue 44: a phase lasts at least ``phase_time.TRACKING`` time constants of the controller's
velocity loop (``run_warnings.loop_inertia`` / K), so that a heavier arm than the RV-M1 gets
phases its model-free controller tracks (a line on the Panda, the UR5e and the iiwa 14)."""

import numpy as np
import pytest

from ptint_drake.simulation.scenario import load_scenario
from ptint_drake.verdict.run_warnings import loop_inertia
from ptint_drake.worlds.pick import phase_time
from ptint_drake.worlds.pick.phase_time import MARGIN, TRACKING, PhaseTimes


def _mass_matrix(model: PhaseTimes, q: np.ndarray) -> np.ndarray:
    plant = model.plant
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, model.instance, q)
    cols = plant.GetVelocitiesFromArray(model.instance, np.arange(plant.num_velocities(), dtype=float))
    return plant.CalcMassMatrix(context)[np.ix_(cols.astype(int), cols.astype(int))]


@pytest.fixture(scope="module")
def rvm1() -> PhaseTimes:
    return PhaseTimes.of(load_scenario("conveyor_pick_place"))


@pytest.fixture(scope="module")
def panda() -> PhaseTimes:
    return PhaseTimes.of(load_scenario("pick_panda"))


def test_a_five_joint_arm_s_loop_inertia_is_its_mass_matrix_s_largest_eigenvalue(rvm1):
    """J (6 × 5) has full column rank and the exact J⁺: J⁺J = I, so the nonzero eigenvalues of
    J M⁻¹ J⁺ are those of M⁻¹ and the slowest mode is M's largest eigenvalue (the sixth, a
    direction J cannot move, left out)."""
    assert rvm1.damping == 0.0
    q = rvm1.q0
    found = loop_inertia(rvm1.plant, rvm1.tool, np.array([q]), 0.0, rvm1.instance, rvm1.rot_scale, 0.0)
    assert found == pytest.approx(np.linalg.eigvalsh(_mass_matrix(rvm1, q)).max(), rel=1e-6)


def test_a_payload_makes_the_loop_slower_and_the_panda_s_is_twenty_times_the_rv_m1_s(rvm1, panda):
    """Measured at the start postures: RV-M1 0.137 kg·m², the Panda with its hand 2.75 (at K = 50
    a time constant of 2.7 ms against 55 ms)."""
    def inertia(model, payload):
        return loop_inertia(model.plant, model.tool, np.array([model.q0]), payload, model.instance,
                            model.rot_scale, model.damping)
    light, heavy = inertia(panda, 0.0), inertia(panda, 2.0)
    assert heavy > light
    assert light > 15.0 * inertia(rvm1, 0.0)


def test_a_short_lift_on_the_panda_lasts_tracking_time_constants_and_a_softer_gain_longer(panda):
    """A 5 cm lift holding 2 kg at the Panda's start: the torque and speed limits alone would
    allow less; the tf is ``TRACKING`` × ``MARGIN`` × the loop's time constant, which halving K
    doubles."""
    context = panda.arm.CreateDefaultContext()
    panda.arm.SetPositions(context, panda.q0)
    x = panda.frame.CalcPoseInWorld(context).translation()
    top = x + [0.0, 0.0, 0.05]
    tf = panda.min_tf(x, top, None, 2.0)
    postures = next(iter(panda.postures.values()))
    bound = TRACKING * loop_inertia(panda.plant, panda.tool, postures, 2.0, panda.instance, panda.rot_scale,
                                    panda.damping) / panda.gain
    assert tf == pytest.approx(MARGIN * bound, rel=1e-9)
    assert panda.demand(x, top, tf, None, 2.0) < 0.5  # (the limits would allow a much shorter one)
    softer = PhaseTimes(**{**panda.__dict__, "gain": panda.gain / 2, "postures": {}, "answers": {}})
    assert softer.min_tf(x, top, None, 2.0) == pytest.approx(2.0 * tf, rel=1e-6)


def test_the_rv_m1_s_phases_are_left_to_its_limits(rvm1, monkeypatch):
    """The RV-M1's loop (2.7 ms at K = 50) sets none of its phases, a lift holding 1 kg included:
    the tfs are those of its speed and torque limits alone (``TRACKING`` = 0)."""
    grasp = np.array([0.3, 0.0, 0.15])
    ways = [(grasp, grasp + [0.0, 0.0, 0.05], None, 1.0), (grasp + [0.0, 0.0, 0.04], grasp, None, 0.0),
            (grasp + [0.0, 0.0, 0.05], np.array([0.15, 0.22, 0.165]), None, 1.0)]
    found = [rvm1.min_tf(*way) for way in ways]
    monkeypatch.setattr(phase_time, "TRACKING", 0.0)
    limits_alone = PhaseTimes(**{**rvm1.__dict__, "postures": {}, "answers": {}})
    assert found == [limits_alone.min_tf(*way) for way in ways]
