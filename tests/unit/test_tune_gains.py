"""``ptint tune --gain rot_scale``: accepted by the parser, it sets controller.rot_scale in every
run of the search and brackets the scenario's value; a position task has no rotation to weigh."""

import pytest

from ptint_drake import cli
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, parse_scenario, scenario_text
from ptint_drake.studies import tune


def test_rot_scale_is_a_gain_of_the_parser():
    assert cli.make_parser().parse_args(["tune", "x", "--gain", "rot_scale"]).gain == "rot_scale"
    tune.check_gain("rot_scale", None)


def test_each_run_of_the_search_sets_rot_scale(monkeypatch):
    name, text = scenario_text("conveyor_yaw")
    seen = []

    def fake_simulate(scenario, check):  # records the gains the run was built with, runs nothing
        seen.append((scenario.controller.rot_scale, scenario.controller.K))
        raise RuntimeError("not simulated")

    monkeypatch.setattr(tune, "simulate", fake_simulate)
    row = tune.tune_run(text, name, "rot_scale", 0.37, "nominal", 2.0, 0.05)
    assert row["gains"] == {"rot_scale": 0.37} and not row["ok"]
    assert seen == [(0.37, 50.0)]  # only rot_scale changed
    scenario = parse_scenario(text, name)
    assert tune.gain_value(scenario, "rot_scale") == 0.1
    assert tune.model_bracket(scenario, "rot_scale") == pytest.approx((0.1 / 30, 0.1 * 30))
    gains = tune._all_gains(scenario, "rot_scale", 0.37)
    assert gains == {"K": 50.0, "Lambda": scenario.controller.Lambda, "phi": scenario.controller.phi,
                     "rot_scale": 0.37}


def test_a_position_task_has_no_rot_scale_to_tune(tmp_path, capsys):
    name, text = scenario_text("curve_b075_tf15")
    settings = tune.TuneSettings(gain="rot_scale")
    with pytest.raises(ScenarioError, match="controller.task of this scenario is position"):
        tune.run_tune(LoadedScenario.load(name), settings)
    # and tune.json's gains of a position task stay K, Lambda, phi
    assert set(tune._all_gains(parse_scenario(text, name), "K", 60.0)) == {"K", "Lambda", "phi"}
    out = tmp_path / "out"
    assert cli.main(["tune", "curve_b075_tf15", "--gain", "rot_scale", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--gain: rot_scale" in err and not out.exists()


def test_drift_advice_names_the_damping_already_set():
    """A redundant arm that still drifts with controller.null_space_damping set is told to raise it,
    not to set it (issue 45's arms run with 10)."""
    base = {"gain": "K", "gains": {"K": 75.35}, "margin": 2.0, "variants": ["nominal"],
            "smallest_working": {"per_variant": {"nominal": {"e_tf_norm": 7e-5}}},
            "paper_value": 50.0, "runs": 39, "wall_time_s": 11.0, "self_motion_final": 0.56,
            "drifts": True}
    assert "consider controller.null_space_damping (e.g. 10)" in tune.summary_line(base)
    line = tune.summary_line(base | {"null_space_damping": 10.0})
    assert "drifts with controller.null_space_damping 10: a larger value" in line
    assert "(e.g. 10)" not in line
