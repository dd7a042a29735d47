"""Scenario files written by the package load under every supported Drake (1.51.1 to the newest)."""

import importlib.metadata

import pytest
import yaml
from pydrake.common.yaml import yaml_dump_typed
from pydrake.systems.analysis import SimulatorConfig

from ptint_drake.simulation.scenario import (ScenarioError, bundled_scenarios, dump_dataclass, dump_yaml,
                                             load_scenario, parse_scenario, scenario_text)

DRAKE_FIELDS = set(yaml.safe_load(yaml_dump_typed(SimulatorConfig())))  # the installed Drake's


@pytest.mark.parametrize("name", bundled_scenarios())
def test_dump_yaml_round_trip_is_portable(name):
    scenario = load_scenario(name)
    text = dump_yaml(scenario)
    assert dump_dataclass(parse_scenario(text, name)) == dump_dataclass(scenario)
    simulator = yaml.safe_load(text)["simulator"]
    # only the fields every supported Drake has (Drake 1.51's publish_every_time_step left out)
    assert set(simulator) == DRAKE_FIELDS - {"publish_every_time_step"}


def test_report_config_has_the_installed_drakes_simulator_fields():
    config = dump_dataclass(load_scenario("curve_b075_tf15"))
    assert set(config["simulator"]) == DRAKE_FIELDS
    assert config["simulator"]["integration_scheme"] == "runge_kutta3"


def test_version_specific_simulator_field():
    _, text = scenario_text("curve_b075_tf15")
    text = text.replace("simulator: {", "simulator: {publish_every_time_step: false, ")
    assert "publish_every_time_step" in text
    if "publish_every_time_step" in DRAKE_FIELDS:  # Drake 1.51
        assert parse_scenario(text).simulator.publish_every_time_step is False
    else:
        with pytest.raises(ScenarioError, match=r"simulator\.publish_every_time_step: unknown field "
                                                r"\(a field of other Drake versions, not of the installed "
                                                + importlib.metadata.version("drake")):
            parse_scenario(text)
