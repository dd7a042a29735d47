"""The one ``--set`` mechanism (scenario_yaml.override_text, scenario.LoadedScenario and
parse_with_overrides): list items, nested keys, one-line errors naming the key or the field."""

import pytest

from ptint_drake.config.yaml_io import override_text, split_path
from ptint_drake.simulation.scenario import (LoadedScenario, ScenarioError, dump_yaml, parse_scenario,
                                             parse_with_overrides, scenario_text)

NAME, TEXT = scenario_text("assembly")


def test_list_items_and_nested_keys_reach_their_field_only():
    base = parse_scenario(TEXT, NAME)
    s = parse_with_overrides(TEXT, ["interceptions[1].target.linear.velocity=[0, 0.2, 0]",
                                    "interceptions[2].tf=1.5", "plant.disturbance.amplitude=[1, 2, 3]",
                                    "measurement.noise_std=1e-5", "controller.type=pd"], NAME)
    assert list(s.interceptions[1].target.linear.velocity) == [0.0, 0.2, 0.0]
    assert s.interceptions[2].tf == 1.5
    assert list(s.plant.disturbance.amplitude) == [1.0, 2.0, 3.0]  # mappings the file does not have
    assert s.measurement.noise_std == 1e-5  # 1e-5 is a number (YAML 1.2), not a string
    assert s.controller.type == "pd"
    # everything else is the file's
    assert s.interceptions[0] == base.interceptions[0]
    assert s.interceptions[1].start == base.interceptions[1].start
    assert list(s.interceptions[1].target.linear.start) == list(base.interceptions[1].target.linear.start)
    assert s.controller.K == base.controller.K and s.duration == base.duration


def test_a_yaml_mapping_is_the_same_overrides_as_key_value_strings():
    pairs = parse_with_overrides(TEXT, ["controller.K=40", "plant.mass_scale=1.5",
                                        "simulator.accuracy=1e-6"], NAME)
    mapping = parse_with_overrides(TEXT, "{controller: {K: 40}, plant: {mass_scale: 1.5}, "
                                         "simulator: {accuracy: 1.0e-6}}", NAME)
    assert dump_yaml(pairs) == dump_yaml(mapping)
    assert pairs.controller.K == 40.0 and pairs.plant.mass_scale == 1.5


def test_a_whole_mapping_value_replaces_the_node():
    s = parse_with_overrides(TEXT, ["plant.disturbance={step: [0, 5, 0], step_time: 0.5}"], NAME)
    assert list(s.plant.disturbance.step) == [0.0, 5.0, 0.0] and s.plant.disturbance.step_time == 0.5


def test_loaded_scenario_text_rebuilds_the_same_scenario():
    loaded = LoadedScenario.load("assembly", ["interceptions[0].tf=0.6", "controller.K=45"])
    assert loaded.name == "assembly" and loaded.scenario.name == "assembly"
    assert loaded.scenario.interceptions[0].tf == 0.6
    assert dump_yaml(parse_scenario(loaded.text, loaded.name)) == dump_yaml(loaded.scenario)
    plain = LoadedScenario.load("assembly")
    assert plain.text == TEXT  # without overrides the file's own text goes to the workers
    assert override_text(TEXT, []) is TEXT and override_text(TEXT, "{}") is TEXT


@pytest.mark.parametrize("key, parts", [
    ("controller.K", ["controller", "K"]),
    ("interceptions[12].target.linear.velocity", ["interceptions", 12, "target", "linear", "velocity"]),
])
def test_split_path(key, parts):
    assert split_path(key) == parts


BAD = {  # override → the whole one-line message
    "interceptions[3].tf=1":
        "--set interceptions[3].tf: index 3 out of range (interceptions has 3 items)",
    "controller.K[0]=1": "--set controller.K[0]: controller.K is not a list, it cannot be indexed",
    "interceptions.tf=1": "--set interceptions.tf: interceptions is a list (use [i])",
    "duration.x=1": "--set duration.x: duration is not a mapping (5.0)",
    "interceptions[0.tf=1":
        "--set interceptions[0.tf: not a field path (expected e.g. controller.K or interceptions[0].tf)",
    "a..b=1": "--set a..b: not a field path (expected e.g. controller.K or interceptions[0].tf)",
    "duration": "--set: expected key=value, got 'duration'",
    "controller.foo=1": "--set: controller.foo: unknown field (known: ",
    "controller.K=[": "--set controller.K: value '[' is not valid YAML",
    "controller.K=abc": "--set: controller.K: expected a number, got 'abc'",
    "interceptions[0].beta=2": "--set: interceptions[0].beta: must be in (0, 1), got 2.0",
    "controller.type=lqr": "--set: controller.type: must be one of ",
}


@pytest.mark.parametrize("pair", sorted(BAD))
def test_a_bad_override_is_one_line_naming_its_key_or_field(pair):
    with pytest.raises(ScenarioError) as err:
        parse_with_overrides(TEXT, [pair], NAME)
    message = str(err.value)
    assert message.startswith(BAD[pair]) and "\n" not in message, message


def test_overrides_apply_in_order_and_the_first_bad_one_is_reported():
    with pytest.raises(ScenarioError, match=r"^--set a\.\.b: "):
        parse_with_overrides(TEXT, ["controller.K=40", "a..b=1", "duration"], NAME)


def test_an_error_of_the_file_itself_is_not_blamed_on_the_override():
    bad_file = TEXT.replace("duration: 5.0", "duration: five")
    assert bad_file != TEXT
    with pytest.raises(ScenarioError) as err:
        parse_with_overrides(bad_file, ["controller.K=40"], NAME)
    assert str(err.value).startswith("duration: expected a number")
    with pytest.raises(ScenarioError, match=r"^scenario YAML: malformed"):
        parse_with_overrides(TEXT + "\n  : [\n", ["controller.K=40"], NAME)
