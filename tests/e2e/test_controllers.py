"""The controller slot: every controller through the station, the one verdict, plant variants."""

import numpy as np
import pytest
from arms import OFFSET_ARM
from conftest import run_cached

from ptint_drake.robot.plant import make_plant
from ptint_drake.simulation import build, simulate
from ptint_drake.simulation.scenario import ScenarioError, apply_variant, load_scenario, parse_scenario
from ptint_drake.verdict.metrics import Criteria, Reason, segment_reasons, verdict

STATIC_ON_OFFSET_ARM = """
duration: 2.5
robot: {{model: {model}, end_effector: hand, initial_q_deg: [17.2, 28.6, 68.8]}}
controller: {{type: {controller}}}
interceptions:
  - {{start: 0.0, tf: 1.0, beta: 0.75, target: {{linear: {{start: {target}, velocity: [0, 0, 0]}}}}}}
"""


def _gripper(scenario) -> np.ndarray:
    plant = make_plant(scenario)
    context = plant.CreateDefaultContext()
    plant.SetPositions(context, np.radians(scenario.robot.initial_q_deg))
    return plant.GetFrameByName(scenario.robot.end_effector).CalcPoseInWorld(context).translation()


@pytest.mark.parametrize("controller", ["ptsmc", "pd", "smc", "ct_quintic"])
def test_every_controller_reaches_a_static_target_on_an_unseen_arm(tmp_path, controller):
    urdf = tmp_path / "offset_arm.urdf"
    urdf.write_text(OFFSET_ARM)
    probe = parse_scenario(STATIC_ON_OFFSET_ARM.format(model=urdf, controller=controller,
                                                       target="[0.3, 0.1, 0.5]"))
    start = _gripper(probe)
    target = (start + np.array([0.03, -0.03, 0.02])).tolist()
    scenario = parse_scenario(STATIC_ON_OFFSET_ARM.format(model=urdf, controller=controller,
                                                          target=target))
    result = simulate(scenario)
    assert result.metrics["controller"]["type"] == controller
    final = np.linalg.norm(result.series["e_true"][-1])
    assert final < 1e-3, f"{controller}: |e| at the end {final * 1e3:.3f} mm"


def test_ct_quintic_with_the_exact_model_meets_a_moving_target_at_tf():
    scenario = load_scenario("curve_b075_tf15")
    scenario.controller.type = "ct_quintic"
    m = simulate(scenario).metrics
    assert m["controller"]["model_based"]
    assert m["segments"][0]["e_tf_norm"] < 1e-3
    assert m["status"] == "ok"


def test_metrics_come_from_the_plant_state_not_the_controller():
    """The fused interceptor's own x is its business; the metrics compute x from q."""
    result = run_cached("curve_b075_tf15")  # the session's run of it (runs are deterministic)
    series = result.series
    # the error is against the true target, recomputed independently here
    from ptint_drake.systems.task.targets import SinusoidTarget  # noqa: PLC0415

    truth = SinusoidTarget([0.24, 0.0, 0.3], [0.1, 0.1, 0.1], 1.5, [0.0, np.pi / 2, 0.0])
    expected = series["x"] - np.array([truth.evaluate(t)[0:3] for t in series["t"]])
    np.testing.assert_allclose(series["e_true"], expected, atol=1e-12)
    plant = build(result.scenario, log=False).plant
    context = plant.CreateDefaultContext()
    tool = plant.GetFrameByName("tool")
    for k in range(0, len(series["t"]), 97):
        plant.SetPositions(context, series["q"][k])
        np.testing.assert_allclose(series["x"][k], tool.CalcPoseInWorld(context).translation(), atol=1e-12)


def _seg(e0=0.05, half=0.025, e_tf=1e-4, hold=5e-4):
    return {"e0_norm": e0, "e_half_norm": half, "e_tf_norm": e_tf, "edot_tf_norm": 0.0,
            "e_hold_max_norm": hold}


@pytest.mark.parametrize("seg, reasons", [
    (_seg(), []),
    (_seg(e_tf=2e-3, hold=2e-3), ["late"]),
    (_seg(half=0.01), ["early"]),
    (_seg(hold=4e-3), ["hold"]),
    (_seg(e0=5e-3, half=1e-4), []),  # starting within 1 cm: cannot arrive early
    (_seg(e_tf=None, hold=None), ["late"]),
    (_seg(e_tf=2e-3, half=0.001, hold=5e-3), ["late", "early", "hold"]),
])
def test_segment_reasons(seg, reasons):
    assert segment_reasons(seg, Criteria()) == reasons


def test_verdict_uses_the_scenario_criteria_and_margin():
    metrics = {"segments": [_seg(e_tf=2e-3, hold=2.5e-3)]}
    assert verdict(metrics, Criteria()) == ("missed", [Reason(0, "late")])
    assert str(verdict(metrics, Criteria())[1][0]) == "segment 0: late"
    assert verdict(metrics, Criteria(e_tf=3e-3, hold=5e-3)) == ("ok", [])
    assert verdict(metrics, Criteria(e_tf=3e-3, hold=5e-3), margin=2.0)[1] == [Reason(0, "late")]
    failed = {"segments": [_seg()], "failure": {"message": "diverged at t = 1 s"}}
    status, reasons = verdict(failed, Criteria())
    assert (status, [str(r) for r in reasons]) == ("failed", ["diverged at t = 1 s"])
    assert reasons[0].as_dict() == {"segment": None, "code": "failed", "message": "diverged at t = 1 s"}
    assert Reason.from_dict(Reason(2, "hold").as_dict()) == Reason(2, "hold")


def test_criteria_are_read_from_the_scenario():
    s = parse_scenario(load_scenario_text() + "criteria: {e_tf: 0.002, hold: 0.004}\n")
    assert (s.criteria.e_tf, s.criteria.hold, s.criteria.half_fraction) == (0.002, 0.004, 0.25)
    with pytest.raises(ScenarioError, match=r"^criteria\.hold: must be > 0"):
        parse_scenario(load_scenario_text() + "criteria: {hold: -1}\n")


def load_scenario_text() -> str:
    from ptint_drake.simulation.scenario import scenario_text  # noqa: PLC0415

    return scenario_text("curve_b075_tf15")[1]


def test_plant_variants_scale_links_and_rotors():
    base = load_scenario("curve_b075_tf15")
    assert apply_variant(base, "mass_x1.5").plant.mass_scale == 1.5
    assert apply_variant(base, "payload_0.5kg").plant.payload_kg == 0.5
    assert apply_variant(base, "nominal").plant.mass_scale == 1.0 and base.plant.mass_scale == 1.0
    for bad in ("mass_x", "mass_x-1", "heavy", "payload_2", "payload_xkg"):
        with pytest.raises(ScenarioError, match=r"^variant: unknown plant variant"):
            apply_variant(base, bad)
    nominal = build(base, log=False).plant
    plant = build(apply_variant(base, "mass_x1.5"), log=False).plant
    context = plant.CreateDefaultContext()  # the variant is in the station's defaults
    for index in plant.GetJointActuatorIndices():
        rotor = nominal.get_joint_actuator(index).default_rotor_inertia()
        if rotor > 0:
            assert plant.get_joint_actuator(index).rotor_inertia(context) == pytest.approx(1.5 * rotor)


@pytest.mark.both_ends
@pytest.mark.parametrize("controller, implementation", [
    ("ptsmc", "fused"), ("ptsmc", "blocks"), ("pd", "fused"), ("smc", "fused")])
def test_model_free_controllers_never_evaluate_dynamics(controller, implementation, dynamics_calls):
    """No dynamics call during a whole run through the slot (the checks before the run, which
    may use the model, are off)."""
    calls = dynamics_calls
    scenario = load_scenario("curve_b075_tf15")
    probe = build(scenario, log=False).plant
    probe.CalcGravityGeneralizedForces(probe.CreateDefaultContext())  # the spy works
    assert calls == ["CalcGravityGeneralizedForces"]
    calls.clear()
    scenario.controller.type, scenario.controller.implementation = controller, implementation
    scenario.duration = 1.5
    result = simulate(scenario, check=False)
    assert result.metrics["segments"][0]["e_tf_norm"] < 0.01  # it did chase the target
    assert calls == []


@pytest.mark.slow
def test_null_space_damping_keeps_a_redundant_arm_near_its_posture(tmp_path):
    """J⁺ leaves a redundant arm's self-motion free; the optional null-space term (off by
    default) damps it toward the start posture without changing the interception."""
    from heavy_arm import heavy_arm_scenario, heavy_arm_urdf  # noqa: PLC0415

    urdf = tmp_path / "heavy6.urdf"
    urdf.write_text(heavy_arm_urdf())
    drift = {}
    # D = 10 at the default rate (docs/own_arm.md) on the fused law; the blocks against the fused
    # law at D = 4, r = 8 s⁻¹ (as damped, and less stiff for the integrator: 3,000 steps, not 6,800)
    runs = [("fused", 0.0, 2.0), ("fused", 10.0, 2.0), ("fused", 4.0, 8.0), ("blocks", 0.0, 2.0),
            ("blocks", 4.0, 8.0)]
    for implementation, D, rate in runs:
        scenario = parse_scenario(heavy_arm_scenario(urdf))
        scenario.controller.null_space_damping, scenario.controller.null_space_rate = D, rate
        scenario.controller.implementation = implementation
        m = simulate(scenario, check=False).metrics
        assert m["status"] == "ok", m["reasons"]
        drift[implementation, D] = m["self_motion_final"]
    assert drift["fused", 0.0] > 1.0 and drift["fused", 10.0] < 0.3 and drift["fused", 4.0] < 0.3
    assert drift["blocks", 0.0] == pytest.approx(drift["fused", 0.0], rel=1e-3)
    assert drift["blocks", 4.0] == pytest.approx(drift["fused", 4.0], rel=1e-3)
    assert load_scenario("curve_b075_tf15").controller.null_space_damping == 0.0  # the paper's law
