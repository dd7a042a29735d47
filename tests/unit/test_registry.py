"""The controller registry and the plugin interface, without simulating: one list of names that
the schema, the validation and compare read; the plugin's params; the segment port."""

import numpy as np
import pytest
from plugin_case import SCENARIO, TYPE

from ptint_drake.controllers import REGISTRY, plugin
from ptint_drake.simulation.scenario import ScenarioError, load_scenario, parse_scenario, scenario_text


def load_scenario_text() -> str:
    return scenario_text("curve_b075_tf15")[1]


def test_unknown_controller_is_one_line_naming_the_field():
    with pytest.raises(ScenarioError, match=r"^controller\.type: must be one of ptsmc, pd, smc, "
                                            r"ct_quintic, or 'module:Class' .*, got 'lqr'$"):
        parse_scenario(load_scenario_text().replace("controller: {", "controller: {type: lqr, "))


def test_the_schema_validation_and_compare_read_the_one_registry():
    """A registered controller's own settings are a scenario block, its name is valid, and
    compare runs it by default — all from ``controllers.REGISTRY``."""
    from dataclasses import fields  # noqa: PLC0415

    from ptint_drake.controllers import CONTROLLERS, REGISTRY  # noqa: PLC0415
    from ptint_drake.simulation.scenario import ControllerConfig  # noqa: PLC0415
    from ptint_drake.studies.compare import DEFAULT_CONTROLLERS  # noqa: PLC0415

    assert CONTROLLERS == tuple(REGISTRY) == DEFAULT_CONTROLLERS
    assert CONTROLLERS[0] == "ptsmc"
    blocks = {f.name: f.type for f in fields(ControllerConfig)}
    own = {name for name, kind in blocks.items()
           if isinstance(kind, type) and hasattr(kind, "__dataclass_fields__")}
    assert own == {e.name for e in REGISTRY.values() if e.config is not None}  # declared = registered
    for entry in REGISTRY.values():
        if entry.config is not None:
            assert blocks[entry.name] is entry.config
        text = load_scenario_text().replace("controller: {", f"controller: {{type: {entry.name}, ")
        scenario = parse_scenario(text)
        assert scenario.controller.type == entry.name


def test_the_segment_port_carries_index_start_and_tf():
    from pydrake.systems.framework import DiagramBuilder  # noqa: PLC0415

    from ptint_drake.systems.task.active_segment import ActiveSegment  # noqa: PLC0415
    from ptint_drake.systems.task.schedule import Schedule, Segment  # noqa: PLC0415

    builder = DiagramBuilder()
    clock = builder.AddSystem(ActiveSegment(Schedule([Segment(0.0, 0.5, 0.75), Segment(0.8, 1.4, 0.5)])))
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    port = clock.get_output_port()
    for t, expected in ((0.0, [0, 0.0, 0.5]), (0.79, [0, 0.0, 0.5]), (0.8, [1, 0.8, 1.4]),
                        (3.0, [1, 0.8, 1.4])):
        context.SetTime(t)
        np.testing.assert_array_equal(port.Eval(clock.GetMyContextFromRoot(context)), expected)


def test_params_are_plugin_only_and_reach_the_plugin():
    text = SCENARIO % TYPE
    with pytest.raises(ScenarioError, match=r"^controller\.params: only a plugin controller"):
        parse_scenario(text.replace(TYPE, "ptsmc"))
    scenario = parse_scenario(text.replace("Kd: 150.0", "Kd: 1e-3, name: x, v: [1, 2]"))
    assert plugin.plain_params(scenario.controller.params) == {"Kp": 2000.0, "Kd": 1e-3, "name": "x",
                                                                "v": [1.0, 2.0]}
    assert TYPE not in REGISTRY and plugin.is_plugin(TYPE) and not plugin.is_plugin("ptsmc")
    assert load_scenario("curve_b075_tf15").controller.params == {}


RECORDING_PLUGIN = '''
import numpy as np
from pydrake.systems.framework import LeafSystem

SEEN = []


class Recorder(LeafSystem):
    """Zero torque; records the params it was built with; reads the object's orientation."""

    def __init__(self, plant, end_effector, params):
        super().__init__()
        SEEN.append(dict(params))
        self.DeclareVectorInputPort("state", plant.num_multibody_states())
        self.DeclareVectorInputPort("target", 9)
        if params.get("task") is not None:
            self.DeclareVectorInputPort("target_rotation", 15)
        self.DeclareVectorOutputPort("actuation", plant.num_actuators(),
                                     lambda context, out: out.SetFromVector(np.zeros(out.size())))
'''

YAW_PLUGIN = """duration: 1.0
robot: {model: rvm1_5dof, end_effector: tool, initial_q_deg: [22.5, 45.0, 30.0, 0.0, 0.0]}
controller: {type: "recorder_plugin:Recorder", task: top_down, params: {Kp: 3.0}}
interceptions:
  - {start: 0.0, tf: 0.5, beta: 0.75,
     target: {linear: {start: [0.20, -0.23, 0.25], velocity: [0.0, 0.1, 0.0]},
              orientation: {rpy_deg: [0.0, 0.0, 30.0]}}}
"""


def test_a_plugin_gets_the_task_in_its_params(tmp_path, monkeypatch):
    from ptint_drake.simulation import build  # noqa: PLC0415

    (tmp_path / "recorder_plugin.py").write_text(RECORDING_PLUGIN)
    monkeypatch.syspath_prepend(str(tmp_path))
    import recorder_plugin  # noqa: PLC0415

    scenario = parse_scenario(YAW_PLUGIN)
    assert plugin.plugin_params(scenario.controller) == {"Kp": 3.0, "task": "top_down"}
    built = build(scenario, log=False)
    assert recorder_plugin.SEEN[-1] == {"Kp": 3.0, "task": "top_down"}
    # it declared target_rotation: the slot connected the object's R_r (Rz(30°)) to it
    system = built.controller.system
    context = built.diagram.CreateDefaultContext()
    R = system.GetInputPort("target_rotation").Eval(system.GetMyContextFromRoot(context))[0:9]
    c, s = np.cos(np.radians(30.0)), np.sin(np.radians(30.0))
    np.testing.assert_allclose(R, [c, -s, 0, s, c, 0, 0, 0, 1], atol=1e-12)
    # a position scenario's plugin gets exactly its own params
    position = parse_scenario(SCENARIO % TYPE)
    assert plugin.plugin_params(position.controller) == {"Kp": 2000.0, "Kd": 150.0}
    with pytest.raises(ScenarioError, match=r"^controller\.params\.task: a plugin gets controller\.task"):
        parse_scenario(YAW_PLUGIN.replace("Kp: 3.0", "Kp: 3.0, task: pose"))
