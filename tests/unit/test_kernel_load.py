"""The interceptor loads its compiled kernels when it is built: a run adds no compiled version.

numba loads (or compiles) a kernel for each new combination of argument types at the call
that first passes it, and a load costs 50-150 ms.  ``InterceptorLaw`` evaluates itself once
when built with the argument types of a simulation, and ``row`` (the telemetry after a run)
passes the same types, so neither the first derivative evaluation nor the telemetry loads
anything: the realtime factor measures the run, and a controller's first step is not slow.
"""

from __future__ import annotations

import pytest

from ptint_drake.controllers.ptsmc.interceptor_row import pose_output, position_output
from ptint_drake.simulation import build, make_simulator
from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text


@pytest.mark.parametrize("name, kernel", [("curve_b075_tf15", position_output), ("curve_pose", pose_output)])
def test_a_run_and_its_telemetry_load_no_kernel(name, kernel):
    _, text = scenario_text(name)
    scenario = parse_with_overrides(text, [], name)
    built = build(scenario)
    loaded = list(kernel.signatures)
    assert loaded, f"{kernel.__name__} is not loaded when the diagram is built"
    simulator = make_simulator(built)
    simulator.AdvanceTo(0.03)
    system = built.controller.system
    context = system.law.GetMyContextFromRoot(simulator.get_context())
    qv, sigma, captured, _ = system.law.loop_values(context)
    rows = system.telemetry_at([0.03], qv[None], sigma[None], captured[None])
    assert rows.shape == (1, system.law.telemetry_size)
    assert list(kernel.signatures) == loaded  # the run and the telemetry used the loaded version


def test_the_telemetry_in_one_call_is_the_row_of_each_sample():
    """``InterceptorLaw.rows`` (``position_rows``: the compiled position path over all logged
    samples in one call) equals ``row`` sample by sample, bit for bit, on perturbed states."""
    import numpy as np

    _, text = scenario_text("curve_b075_tf15")
    scenario = parse_with_overrides(text, [], "curve_b075_tf15")
    law = build(scenario, log=False).controller.system.law
    rng = np.random.default_rng(3)
    k = 40
    t = np.sort(rng.uniform(0.0, scenario.duration, k))
    t[5] = t[4]  # a repeated time (the kernels' memo)
    qv = np.radians([10.0, 40.0, 35.0, 0.0, 0.0, 0.0]) + rng.normal(0.0, 0.1, (k, 6))
    sigma = rng.normal(0.0, 1e-3, (k, 3))
    captured = np.tile(np.r_[0.0, rng.normal(0.0, 0.01, 6)], (k, 1))
    batch = law.rows(t, qv, sigma, captured)
    one_by_one = np.array([law.row(*values, None, None) for values in zip(t.tolist(), qv, sigma, captured)])
    assert batch.shape == one_by_one.shape and np.isfinite(batch).all()
    np.testing.assert_array_equal(batch, one_by_one)


def test_the_law_falls_back_to_the_general_kernels_at_a_singular_jacobian():
    """At a singular J (rvm1's elbow at 90°) the lean kernels cannot solve: ``row`` and ``rows``
    (``InterceptorLaw._call``) then give the general kernels' bits, as at any other state."""
    import numpy as np

    _, text = scenario_text("curve_b075_tf15")
    law = build(parse_with_overrides(text, [], "curve_b075_tf15"), log=False).controller.system.law
    qv = np.array([[0.3, 0.2, np.pi / 2, 0.1, -0.2, 0.3], [0.3, 0.2, 0.9, 0.1, -0.2, 0.3]])
    sigma = np.array([[0.01, 0.0, -0.01]] * 2)
    captured = np.array([[0.0, 0.02, -0.01, 0.03, 0.0, 0.0, 0.0]] * 2)
    t = np.array([0.4, 0.5])
    for k in range(2):
        args = (t[k], qv[k], sigma[k], captured[k], None)
        row = law.row(*args)
        assert np.isfinite(row).all()
        np.testing.assert_array_equal(row, law.row(*args, path="general"))
    np.testing.assert_array_equal(law.rows(t, qv, sigma, captured),
                                  law.rows(t, qv, sigma, captured, path="general"))


@pytest.mark.parametrize("name", ["curve_b075_tf15", "curve_pose"])
def test_the_telemetry_passes_the_kernels_the_simulations_argument_types(name):
    """``rows`` (the telemetry's batch kernel) hands the row kernel each sample as the simulation
    hands it the ``loop`` input: read-only where the bindings' is (Drake 1.51), so numba compiles
    the row kernel (and its general version) once, not once more for the telemetry's array."""
    import numba
    import numpy as np

    _, text = scenario_text(name)
    built = build(parse_with_overrides(text, [], name), log=False)
    law = built.controller.system.law
    simulator = make_simulator(built)
    simulator.AdvanceTo(0.01)
    context = law.GetMyContextFromRoot(simulator.get_context())
    u_sim = law._loop_in.EvalBasicVector(context).value()  # what ``_calc_packed_output`` passes
    calls = []
    call = law._call
    law._call = lambda kernel, *args, path="auto": calls.append(args) or call(kernel, *args, path=path)
    qv, sigma, captured, _ = law.loop_values(context)
    law.rows(np.array([0.01]), qv[None], sigma[None], captured[None])
    (args,) = calls
    assert numba.typeof(args[1][0]) == numba.typeof(u_sim)
