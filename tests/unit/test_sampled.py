"""Sampled control (``controller.control_period``, ``controllers.hold``) and the discrete plant
(``multibody``: Drake's MultibodyPlantConfig): the checks, the hold in every controller's
diagram, the plant's settings, and what a few milliseconds of simulation log."""

from pathlib import Path

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.primitives import ZeroOrderHold

from ptint_drake import cli
from ptint_drake.controllers.hold import HOLD_NAME
from ptint_drake.robot.plant import make_plant
from ptint_drake.simulation import build
from ptint_drake.simulation.scenario import LoadedScenario, ScenarioError, dump_yaml, parse_scenario
from ptint_drake.verdict.run_warnings import sampled_control_warnings

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CURVE = "curve_b075_tf15"
DISCRETE = "multibody={time_step: 0.001, discrete_contact_approximation: sap}"


def scenario(*overrides):
    return LoadedScenario.load(CURVE, overrides).scenario


BAD = [
    (("controller.control_period=-0.001",), "controller.control_period: must be > 0 s"),
    (("controller.control_period=.inf",), "controller.control_period: must be > 0 s"),
    (("controller.control_period=.nan",), "controller.control_period: must be > 0 s"),
    ((DISCRETE,), "controller.control_period: a discrete plant (multibody.time_step 0.001 s) needs"),
    (("multibody={time_step: -0.001}",), "multibody.time_step: must be >= 0"),
    (("controller.control_period=0.001", "multibody={penetration_allowance: 0}"),
     "multibody.penetration_allowance: must be > 0"),
    (("multibody={time_stp: 0.001}",), "multibody.time_stp: unknown field (known: time_step, "),
    (("multibody.time_step=fast",), "multibody.time_step: expected a number, got 'fast'"),
]


@pytest.mark.parametrize("overrides, message", BAD, ids=[" ".join(o) for o, _ in BAD])
def test_bad_settings_are_one_line_naming_the_field(overrides, message):
    with pytest.raises(ScenarioError) as err:
        scenario(*overrides)
    text = str(err.value)
    assert text.startswith(f"--set: {message}") and "\n" not in text, text


def test_an_approximation_drake_does_not_know_names_multibody():
    bad = scenario("controller.control_period=0.001",
                   "multibody={time_step: 0.001, discrete_contact_approximation: exact}")
    with pytest.raises(ScenarioError, match=r"^multibody: .*discrete_contact_approximation.*'exact'"):
        make_plant(bad)


def test_cli_exit_2_on_a_period_that_is_not_positive(capsys):
    assert cli.main(["run", CURVE, "--set", "controller.control_period=-1", "--no-replay", "--no-figures",
                     "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "controller.control_period: must be > 0 s" in err and err.count("\n") == 1, err


def test_continuous_control_adds_no_hold_and_a_period_adds_one():
    plain = build(scenario(), log=False).diagram
    assert not plain.HasSubsystemNamed(HOLD_NAME)
    zero = build(scenario("controller.control_period=0"), log=False).diagram
    assert _systems(zero) == _systems(plain) and len(zero.connection_map()) == len(plain.connection_map())
    held = build(scenario("controller.control_period=0.002"), log=False).diagram
    assert held.HasSubsystemNamed(HOLD_NAME)


def _systems(diagram) -> list:
    return [(system.get_name(), type(system).__name__) for system in diagram.GetSystems()]


def _hold_wiring(diagram):
    """(hold, its input's source system, the system.port names its output feeds)."""
    hold = diagram.GetSubsystemByName(HOLD_NAME)
    source, dests = None, set()
    for (to_system, to_port), (from_system, _) in diagram.connection_map().items():
        if to_system is hold:
            source = from_system
        if from_system is hold:
            dests.add(f"{to_system.get_name()}.{to_system.get_input_port(to_port).get_name()}")
    return hold, source, dests


CONTROLLERS = [("ptsmc", ("controller.implementation=fused",), "interceptor"),
               ("ptsmc", ("controller.implementation=blocks",), "interceptor_controller"),
               ("pd", (), "pd"), ("smc", (), "smc"), ("ct_quintic", (), "ct_quintic"),
               ("task_space_pd:TaskSpacePD", ("controller.params={Kp: 2000.0, Kd: 150.0}",), "TaskSpacePD")]


@pytest.mark.parametrize("type_, extra, controller", CONTROLLERS, ids=[f"{c[0]} {c[1]}" for c in CONTROLLERS])
def test_every_controller_drives_the_station_through_the_hold(type_, extra, controller):
    s = scenario(f"controller.type={type_}", "controller.control_period=0.004", *extra)
    s.plugin_folders = (str(EXAMPLES),)  # as loading a scenario file in that folder sets it
    built = build(s, log=True)
    hold, source, dests = _hold_wiring(built.diagram)
    assert isinstance(hold, ZeroOrderHold) and hold.period() == 0.004 and hold.offset() == 0.0
    nu = built.plant.num_actuators()
    assert hold.get_input_port().size() == hold.get_output_port().size() == nu == 3
    assert source.get_name() == controller and "station.actuation" in dests
    assert HOLD_NAME in built.loggers  # the held torque is what the run's tau reports
    assert any("sampled control: period 4 ms" in n for n in built.controller.notes)


def test_the_logged_torque_is_held_between_samples():
    """5 ms of the paper's curve at a 1 ms period: tau changes only at the sample instants."""
    built = build(scenario("controller.control_period=0.001"))
    simulator = Simulator(built.diagram)
    simulator.AdvanceTo(0.005)
    log = built.loggers[HOLD_NAME].FindLog(simulator.get_context())
    t, u = log.sample_times(), log.data().T
    k = np.floor(t * 1e3 - 1e-9)  # the sample a logged value was taken at (the value up to t)
    for sample in range(5):
        rows = u[(k == sample) & (t > 0)]
        assert len(rows) >= 1 and np.all(rows == rows[0]), sample
    assert not np.allclose(u[k == 2], 0.0)  # the controller's torque (zero at t = 0: s(0) = 0)


def test_a_discrete_plant_has_the_config_and_keeps_the_mass_variant():
    plant = make_plant(scenario("controller.control_period=0.001", DISCRETE))
    heavy = make_plant(scenario("controller.control_period=0.001", DISCRETE, "plant.mass_scale=1.5"))
    assert plant.time_step() == heavy.time_step() == 0.001
    assert plant.get_discrete_contact_approximation().name == "kSap"
    assert heavy.get_discrete_contact_approximation().name == "kSap"
    masses = [plant.GetBodyByName(n).default_mass() for n in ("waist", "upper_arm", "forearm")]
    scaled = [heavy.GetBodyByName(n).default_mass() for n in ("waist", "upper_arm", "forearm")]
    assert np.allclose(scaled, 1.5 * np.array(masses)) and min(masses) > 0
    assert make_plant(scenario()).time_step() == 0.0


def test_a_discrete_scenario_dumps_and_loads_back():
    s = scenario("controller.control_period=0.001", DISCRETE)
    again = parse_scenario(dump_yaml(s))
    assert again.multibody.time_step == 0.001 and again.multibody.discrete_contact_approximation == "sap"
    assert again.controller.control_period == 0.001
    assert parse_scenario(dump_yaml(scenario())).multibody is None


def test_a_period_of_2_ms_or_more_warns():
    assert sampled_control_warnings(scenario("controller.control_period=0.001")) == []
    assert sampled_control_warnings(scenario()) == []
    (warning,) = sampled_control_warnings(scenario("controller.control_period=0.002"))
    assert warning.startswith("sampled control at 2 ms: expect a hold error")
