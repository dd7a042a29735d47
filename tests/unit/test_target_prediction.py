"""target_prediction: the one selector of the active object's target — the IMMs' polynomials
selected and evaluated (compiled), or estimates passed on."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator

from ptint_drake.systems.estimation.target_prediction import (POLYNOMIAL_SIZE, ActiveTargetSelector,
                                                              PolynomialTargetSelector)
from ptint_drake.systems.task.schedule import Schedule, Segment


def _value(c, t):
    dt = t - c[0]
    return c[1:10] + dt * c[10:19] + (dt * dt) * c[19:28]


def test_selects_the_active_segment_and_evaluates_its_polynomial():
    """Before the second start: object 0's c₀ + Δt c₁ + Δt² c₂ (also before the first start);
    from it on: object 1's — to rounding, whatever the (arbitrary) coefficients."""
    schedule = Schedule([Segment(0.5, 0.2, 0.5), Segment(1.0, 0.5, 0.5)])
    selector = ActiveTargetSelector(schedule=schedule, count=2, polynomial=True)
    context = selector.CreateDefaultContext()
    rng = np.random.default_rng(0)
    c = [np.r_[0.3, rng.normal(size=27)], np.r_[0.95, rng.normal(size=27)]]
    for i in range(2):
        selector.GetInputPort(f"target_{i}").FixValue(context, c[i])
    for t, i in ((0.0, 0), (0.7, 0), (0.999, 0), (1.0, 1), (5.0, 1)):
        context.SetTime(t)
        np.testing.assert_allclose(selector.get_target_output_port().Eval(context), _value(c[i], t),
                                   rtol=1e-14, atol=1e-14)
    with pytest.raises(ValueError, match=r"^count: "):
        ActiveTargetSelector(schedule=schedule, count=3, polynomial=True)
    with pytest.raises(ValueError, match=r"^size: "):
        ActiveTargetSelector(schedule=schedule, count=2, size=15, polynomial=True)


def test_one_object_runs_in_a_simulator():
    """All zeros (an estimator before its first sample) give zeros; a Simulator can run it."""
    selector = ActiveTargetSelector(schedule=Schedule([Segment(0.0, 1.0, 0.5)]), count=1, polynomial=True)
    simulator = Simulator(selector)
    context = simulator.get_mutable_context()
    selector.GetInputPort("target_0").FixValue(context, np.zeros(POLYNOMIAL_SIZE))
    simulator.AdvanceTo(0.1)
    np.testing.assert_array_equal(selector.get_target_output_port().Eval(context), np.zeros(9))


def test_passes_on_the_active_input_of_any_width():
    """Without ``polynomial``: the active segment's input as it is (15 wide: orientations)."""
    schedule = Schedule([Segment(0.5, 0.2, 0.5), Segment(1.0, 0.5, 0.5)])
    selector = ActiveTargetSelector(schedule=schedule, count=2, size=15)
    context = selector.CreateDefaultContext()
    for i in range(2):
        selector.GetInputPort(f"target_{i}").FixValue(context, (-1.0) ** i * np.arange(15.0))
    for t, i in ((0.0, 0), (0.999, 0), (1.0, 1)):
        context.SetTime(t)
        np.testing.assert_array_equal(selector.get_target_output_port().Eval(context),
                                      (-1.0) ** i * np.arange(15.0))


def test_the_earlier_name_is_the_polynomial_selector():
    selector = PolynomialTargetSelector(schedule=Schedule([Segment(0.0, 1.0, 0.5)]), count=1)
    assert isinstance(selector, ActiveTargetSelector)
    assert selector.GetInputPort("target_0").size() == POLYNOMIAL_SIZE
    assert selector.get_target_output_port().size() == 9
