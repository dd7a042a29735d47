"""The three baseline controllers (pd, smc, ct_quintic): each law on fixed inputs, each in
closed loop on the RV-M1, the segment events, and the model-free ones never touching dynamics."""

import numpy as np
import pytest
from pydrake.common.yaml import yaml_load_typed
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import MultibodyPlant
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder, LeafSystem
from pydrake.systems.primitives import ConstantVectorSource

from ptint_drake.controllers.baseline import TaskSpaceBaseline
from ptint_drake.controllers.ct_quintic import CtQuinticConfig, CtQuinticController, quintic_eval
from ptint_drake.controllers.pd import PDConfig, PDController
from ptint_drake.controllers.ptsmc.builder import ControllerGains
from ptint_drake.controllers.smc import FirstOrderSMC, SMCConfig
from ptint_drake.robot import rvm1
from ptint_drake.systems.task.schedule import Schedule, Segment
from ptint_drake.systems.task.signals import TARGET_PORT, TARGET_PORT_SIZE
from ptint_drake.systems.task.targets import SinusoidTarget

THETA0 = np.radians(rvm1.START_THETA_DEG)
CURVE = SinusoidTarget([0.24, 0.0, 0.3], [0.1] * 3, 1.5, [0.0, np.pi / 2, 0.0])
STEP = np.array([0.03, -0.03, 0.03])  # 5.2 cm from the start pose
DQ_DTHETA = np.array([[1.0, 0, 0], [0, 1, 0], [0, -2, -1]])  # q = (θ1, θ2, −(2θ2 + θ3))


def _plant():
    plant = MultibodyPlant(time_step=0.0)
    Parser(plant).AddModels(str(rvm1.model_path("rvm1")))
    plant.Finalize()
    return plant


def _make(kind, plant, schedule, predict=None, nominal_plant=None):
    frame = plant.GetFrameByName(rvm1.END_EFFECTOR)
    if kind == "pd":
        return PDController(plant=plant, frame=frame, schedule=schedule, config=PDConfig())
    if kind == "smc":
        return FirstOrderSMC(plant=plant, frame=frame, schedule=schedule, config=SMCConfig())
    return CtQuinticController(plant=plant, frame=frame, schedule=schedule, config=CtQuinticConfig(),
                               nominal_plant=nominal_plant or _plant(), predict=predict)


def _hand_kinematics(theta, thetadot):
    """x, ẋ, J from the paper's equations (rvm1.paper_fk / paper_jacobian) through q(θ)."""
    J = rvm1.paper_jacobian(rvm1.q_from_theta(theta)) @ DQ_DTHETA
    return rvm1.paper_fk(rvm1.q_from_theta(theta)), J @ thetadot, J


def _fixed(system, t, theta, thetadot, target):
    ctx = system.CreateDefaultContext()
    ctx.SetTime(t)
    system.GetInputPort("state").FixValue(ctx, np.concatenate([theta, thetadot]))
    system.GetInputPort("target").FixValue(ctx, target)
    system.ExecuteInitializationEvents(ctx)
    return ctx


THETADOT = np.array([0.2, -0.1, 0.3])
TARGET = np.array([0.22, 0.07, 0.31, 0.1, -0.05, 0.02, 0.0, 0.0, 0.0])


def test_pd_law_on_fixed_inputs():
    pd = _make("pd", _plant(), Schedule([Segment(0.0, 1.5, 0.75)]))
    ctx = _fixed(pd, 0.0, THETA0, THETADOT, TARGET)
    integral = np.array([0.01, -0.02, 0.005])
    ctx.SetContinuousState(integral)
    x, xdot, J = _hand_kinematics(THETA0, THETADOT)
    omega = 8.4 / 1.5
    Kp, Kd, Ki = 3 * 10.0 * omega**2, 3 * 10.0 * omega, 10.0 * omega**3
    assert pd.gains_for(1.5) == pytest.approx({"Kp": Kp, "Kd": Kd, "Ki": Ki, "omega": omega})
    e, edot = x - TARGET[0:3], xdot - TARGET[3:6]
    tau = -J.T @ (Kp * e + Kd * edot + Ki * integral)
    np.testing.assert_allclose(pd.GetOutputPort("tau").Eval(ctx), tau, rtol=1e-9)
    np.testing.assert_allclose(pd.GetOutputPort("u").Eval(ctx), tau, rtol=1e-9)
    tel = pd.GetOutputPort("telemetry").Eval(ctx)
    for name, value in (("x", x), ("xdot", xdot), ("e", e), ("edot", edot), ("tau", tau)):
        np.testing.assert_allclose(tel[pd.layout[name]], value, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(pd.EvalTimeDerivatives(ctx).CopyToVector(), e, atol=1e-12)
    assert PDConfig(Ki=0.0, Kp=100.0).gains_for(1.0)["Ki"] == 0.0


def test_smc_law_on_fixed_inputs():
    smc = _make("smc", _plant(), Schedule([Segment(0.0, 1.5, 0.75)]))
    ctx = _fixed(smc, 0.0, THETA0, THETADOT, TARGET)
    sigma = np.array([0.01, -0.02, 0.005])
    ctx.SetContinuousState(sigma)
    x, xdot, J = _hand_kinematics(THETA0, THETADOT)
    e, edot = x - TARGET[0:3], xdot - TARGET[3:6]
    s = edot + (4.0 / 1.5) * e
    s_x = s + 5.0 * sigma
    tau = -50.0 * np.linalg.solve(J, s_x)
    np.testing.assert_allclose(smc.GetOutputPort("tau").Eval(ctx), tau, rtol=1e-9)
    tel = smc.GetOutputPort("telemetry").Eval(ctx)
    for name, value in (("e", e), ("edot", edot), ("s", s), ("s_x", s_x), ("sigma", sigma)):
        np.testing.assert_allclose(tel[smc.layout[name]], value, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(smc.EvalTimeDerivatives(ctx).CopyToVector(), np.tanh(s / 0.01))
    gains = ControllerGains(K=30.0, phi=0.02, sigma_policy="reset")
    assert SMCConfig.from_gains(gains) == SMCConfig(K=30.0, phi=0.02, sigma_policy="reset")


@pytest.mark.parametrize("kind, policy", [("pd", "integral_policy"), ("smc", "sigma_policy")])
@pytest.mark.parametrize("value", ["keep", "reset"])
def test_segment_start_events(kind, policy, value):
    """A second segment re-triggers: new gains / λ in the discrete state, state kept or reset
    (the one handler of ``baseline_common.TaskSpaceBaseline``)."""
    schedule = Schedule([Segment(0.0, 1.5, 0.75), Segment(2.0, 1.0, 0.75)])
    plant = _plant()
    frame = plant.GetFrameByName(rvm1.END_EFFECTOR)
    if kind == "pd":
        system = PDController(plant=plant, frame=frame, schedule=schedule,
                              config=PDConfig(**{policy: value}))
        expected = [1, *(system.gains_for(1.0)[k] for k in ("Kp", "Kd", "Ki"))]
    else:
        system = FirstOrderSMC(plant=plant, frame=frame, schedule=schedule,
                               config=SMCConfig(**{policy: value}))
        expected = [1, 4.0 / 1.0]
    assert isinstance(system, TaskSpaceBaseline)
    sim = Simulator(system)
    ctx = sim.get_mutable_context()
    system.GetInputPort("state").FixValue(ctx, np.concatenate([THETA0, np.zeros(3)]))
    system.GetInputPort("target").FixValue(ctx, TARGET)
    sim.AdvanceTo(1.999)
    before = ctx.get_continuous_state_vector().CopyToVector()
    assert np.linalg.norm(before) > 0
    sim.AdvanceTo(2.0 + 1e-9)  # the simulator handles the event at 2.0 when it leaves 2.0
    np.testing.assert_allclose(ctx.get_discrete_state(0).value(), expected)
    after = ctx.get_continuous_state_vector().CopyToVector()
    if value == "reset":
        np.testing.assert_allclose(after, 0.0, atol=1e-6)
    else:
        np.testing.assert_allclose(after, before, rtol=1e-2)


@pytest.mark.parametrize("predicted", ["default", "given"])
def test_ct_quintic_plan_at_start(predicted):
    plant = _plant()
    tf = 1.2
    goal = np.array([0.25, 0.02, 0.28, 0.05, 0.1, 0.0])
    predict = (lambda i, t, target: goal) if predicted == "given" else None
    ct = _make("ct", plant, Schedule([Segment(0.0, tf, 0.75)]), predict=predict)
    ctx = _fixed(ct, 0.0, THETA0, THETADOT, TARGET)
    ref = ct.reference
    rctx = ref.GetMyContextFromRoot(ctx)
    np.testing.assert_allclose(ref.GetOutputPort("desired_state").Eval(rctx),
                               np.concatenate([THETA0, THETADOT]), atol=1e-12)
    np.testing.assert_allclose(ref.GetOutputPort("desired_acceleration").Eval(rctx), 0.0, atol=1e-9)
    plan = ref.plan(rctx)
    if predicted == "default":  # constant-acceleration extrapolation of the input (ẍ_r = 0 here)
        goal = np.concatenate([TARGET[0:3] + TARGET[3:6] * tf, TARGET[3:6]])
    np.testing.assert_allclose(plan["x_f"], goal[0:3])
    x_f, _, J_f = _hand_kinematics(plan["q_f"], np.zeros(3))
    assert np.max(np.abs(x_f - goal[0:3])) <= CtQuinticConfig().ik_tolerance + 1e-6
    lam = CtQuinticConfig().pinv_damping  # v_f = Jᵀ(JJᵀ + λ²I)⁻¹ ẋ_f
    np.testing.assert_allclose(plan["v_f"], J_f.T @ np.linalg.solve(J_f @ J_f.T + lam**2 * np.eye(3),
                                                                    goal[3:6]), atol=1e-12)
    q, v, a = quintic_eval(plan["c"], tf)
    np.testing.assert_allclose(np.concatenate([q, v, a]),
                               np.concatenate([plan["q_f"], plan["v_f"], np.zeros(3)]), atol=1e-9)
    tel = ct.GetOutputPort("telemetry").Eval(ctx)
    np.testing.assert_allclose(tel[ct.layout["tau"]], ct.GetOutputPort("tau").Eval(ctx))
    np.testing.assert_allclose(tel[ct.layout["q_d"]], THETA0, atol=1e-12)


def test_ct_quintic_unreachable_target():
    """"raise": a ValueError naming the segment; "nearest": the reachable point closest to it."""
    plant = _plant()
    frame = plant.GetFrameByName(rvm1.END_EFFECTOR)
    schedule = Schedule([Segment(0.0, 1.0, 0.75)])
    far = np.concatenate([[2.0, 0.0, 0.3], np.zeros(6)])  # out of reach now and at tf
    ct = CtQuinticController(plant=plant, frame=frame, schedule=schedule, nominal_plant=_plant(),
                             config=CtQuinticConfig(on_ik_failure="raise"))
    with pytest.raises(ValueError, match="segment 0"):
        _fixed(ct, 0.0, THETA0, np.zeros(3), far)
    ct = _make("ct", plant, schedule)
    ctx = _fixed(ct, 0.0, THETA0, np.zeros(3), far)
    plan = ct.reference.plan(ct.reference.GetMyContextFromRoot(ctx))
    assert not plan["reached"]
    assert ct.GetOutputPort("telemetry").Eval(ctx)[ct.layout["reached"]] == [0.0]
    x_f = _hand_kinematics(plan["q_f"], np.zeros(3))[0]
    # the arm stretched towards it: 0.41 m is the reach of the 0.25 + 0.16 m arms from the shoulder
    np.testing.assert_allclose(np.linalg.norm(x_f - [0, 0, 0.3]), 0.41, atol=1e-3)
    assert x_f[0] > 0.4


class _CurveSource(LeafSystem):
    """[x_r, ẋ_r, ẍ_r] of a target with ``evaluate(t)``."""

    def __init__(self, target):
        super().__init__()
        self.DeclareVectorOutputPort(
            "target", TARGET_PORT_SIZE,
            lambda c, o: o.SetFromVector(target.evaluate(c.get_time())[TARGET_PORT]))


def _closed_loop(kind, schedule, target, predict=None):
    """Plant + target source + controller; returns (simulator, controller, its context)."""
    builder = DiagramBuilder()
    plant = builder.AddSystem(_plant())
    ctrl = builder.AddSystem(_make(kind, _plant(), schedule, predict=predict))
    if isinstance(target, np.ndarray):
        source = builder.AddSystem(ConstantVectorSource(np.concatenate([target, np.zeros(6)])))
    else:
        source = builder.AddSystem(_CurveSource(target))
    builder.Connect(source.get_output_port(0), ctrl.GetInputPort("target"))
    builder.Connect(plant.get_state_output_port(), ctrl.GetInputPort("state"))
    builder.Connect(ctrl.GetOutputPort("u"), plant.get_actuation_input_port())
    sim = Simulator(builder.Build())
    sim.get_mutable_integrator().set_target_accuracy(1e-4)
    ctx = sim.get_mutable_context()
    plant.SetPositions(plant.GetMyMutableContextFromRoot(ctx), THETA0)
    return sim, ctrl, ctrl.GetMyContextFromRoot(ctx)


def _error(ctrl, cctx):
    return np.linalg.norm(ctrl.GetOutputPort("telemetry").Eval(cctx)[ctrl.layout["e"]])


@pytest.mark.parametrize("kind", ["pd", "smc", "ct"])
def test_closed_loop_reaches_static_target(kind):
    """5.2 cm away, tf = 1 s: within 1 mm by 1.5 tf (ct_quintic by tf itself)."""
    ctx0 = (plant := _plant()).CreateDefaultContext()
    plant.SetPositions(ctx0, THETA0)
    x0 = plant.GetFrameByName(rvm1.END_EFFECTOR).CalcPoseInWorld(ctx0).translation()
    sim, ctrl, cctx = _closed_loop(kind, Schedule([Segment(0.0, 1.0, 0.75)]), x0 + STEP)
    sim.AdvanceTo(0.0)
    assert _error(ctrl, cctx) == pytest.approx(np.linalg.norm(STEP))
    sim.AdvanceTo(1.0 if kind == "ct" else 1.5)
    assert _error(ctrl, cctx) <= 1e-3
    sim.AdvanceTo(2.5)
    assert _error(ctrl, cctx) <= 1e-3


def test_ct_quintic_intercepts_the_curve_at_tf():
    """The paper's curve from t = 0, tf = 1.5, exact model and exact predictor: |e(tf)| ≤ 1 mm."""
    def predict(i, t, target):
        return CURVE.evaluate(t)[0:6]
    sim, ctrl, cctx = _closed_loop("ct", Schedule([Segment(0.0, 1.5, 0.75)]), CURVE, predict)
    sim.AdvanceTo(1.5)
    assert _error(ctrl, cctx) <= 1e-3
    sim.AdvanceTo(2.5)  # then follows it by differential IK
    assert _error(ctrl, cctx) <= 1e-3


class _Switching:
    """A static target that jumps to another point at t = 1.5 s (a second interception)."""

    def __init__(self, a, b):
        self.a, self.b = np.concatenate([a, np.zeros(6)]), np.concatenate([b, np.zeros(6)])

    def evaluate(self, t):
        return self.a if t < 1.5 else self.b


def test_ct_quintic_replans_at_each_segment():
    ctx0 = (plant := _plant()).CreateDefaultContext()
    plant.SetPositions(ctx0, THETA0)
    x0 = plant.GetFrameByName(rvm1.END_EFFECTOR).CalcPoseInWorld(ctx0).translation()
    schedule = Schedule([Segment(0.0, 1.0, 0.75), Segment(1.5, 0.8, 0.75)])
    sim, ctrl, cctx = _closed_loop("ct", schedule, _Switching(x0 + STEP, x0 - STEP))
    sim.AdvanceTo(1.0)
    assert _error(ctrl, cctx) <= 1e-3
    sim.AdvanceTo(2.3)
    plan = ctrl.reference.plan(ctrl.reference.GetMyContextFromRoot(sim.get_context()))
    assert (plan["segment"], plan["t0"], plan["t1"]) == (1, 1.5, pytest.approx(2.3))
    assert _error(ctrl, cctx) <= 1e-3


@pytest.mark.parametrize("kind", ["pd", "smc"])
def test_model_free_controllers_never_evaluate_dynamics(kind, dynamics_calls):
    """Every Python call of a MultibodyPlant dynamics method is recorded during a closed-loop run."""
    probe = _plant()
    probe.CalcMassMatrix(probe.CreateDefaultContext())  # the spy works
    assert dynamics_calls == ["CalcMassMatrix"]
    dynamics_calls.clear()
    sim, ctrl, cctx = _closed_loop(kind, Schedule([Segment(0.0, 1.0, 0.75)]), CURVE)
    sim.AdvanceTo(1.0)
    assert _error(ctrl, cctx) < 0.01  # it did chase the target
    assert dynamics_calls == []


def test_configs_load_from_yaml():
    pd = yaml_load_typed(schema=PDConfig, data="settling_factor: 6.0\nKi: 0.0\n")
    assert pd == PDConfig(settling_factor=6.0, Ki=0.0)
    assert yaml_load_typed(schema=SMCConfig, data="lambda_factor: 3.0\nswitching: sat\n") == \
        SMCConfig(lambda_factor=3.0, switching="sat")
    assert yaml_load_typed(schema=CtQuinticConfig, data="omega: 30.0\n") == CtQuinticConfig(omega=30.0)


def test_every_target_port_has_the_one_width():
    """Baselines, the fused system, the blocks' target input and ``TargetSource`` all take
    ``signals.TARGET_PORT_SIZE`` values laid out as ``signals.TARGET`` slots."""
    from ptint_drake.controllers.ptsmc.builder import AddPrescribedTimeInterceptor
    from ptint_drake.systems.task.signals import TARGET as SLOTS
    from ptint_drake.systems.task.targets import TargetSource

    assert TARGET_PORT_SIZE == 9 and TARGET_PORT == slice(0, SLOTS.xddot.stop)
    schedule = Schedule([Segment(0.0, 1.5, 0.75)])
    plant = _plant()
    for kind in ("pd", "smc", "ct_quintic"):
        assert _make(kind, plant, schedule).GetInputPort("target").size() == TARGET_PORT_SIZE
    assert TargetSource(schedule, [CURVE]).GetOutputPort("target").size() == TARGET_PORT_SIZE
    for fused in (True, False):
        builder = DiagramBuilder()
        robot = builder.AddSystem(_plant())
        handles = AddPrescribedTimeInterceptor(builder, robot, robot.GetFrameByName(rvm1.END_EFFECTOR),
                                               schedule, None, fused=fused)
        assert handles.target_input.size() == TARGET_PORT_SIZE


def test_prediction_reads_the_named_slots():
    """ct_quintic's constant-acceleration prediction takes x_r, ẋ_r, ẍ_r from their slots."""
    from ptint_drake.controllers.ct_quintic import constant_acceleration_predict
    from ptint_drake.systems.task.signals import TARGET as SLOTS

    target = np.zeros(9)
    target[SLOTS.x], target[SLOTS.xdot], target[SLOTS.xddot] = [0.2, 0.1, 0.3], [0.1, -0.2, 0.0], [1, 2, 3]
    goal = constant_acceleration_predict(target, 0.5)
    np.testing.assert_allclose(goal[SLOTS.x], [0.2 + 0.05 + 0.125, 0.1 - 0.1 + 0.25, 0.3 + 0.375])
    np.testing.assert_allclose(goal[SLOTS.xdot], [0.1 + 0.5, -0.2 + 1.0, 1.5])
