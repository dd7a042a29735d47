"""Model-based reference baseline: quintic joint-space plan + computed torque.

It is given what the model-free controllers are not, on purpose: the model (a NOMINAL
plant: the simulated one may differ) and the target's future (``predict``).

At every segment start t0 (a Drake event; i = the segment, t1 = t0 + tf):

    [x_f, ẋ_f] = predict(i, t1, target(t0))                 the target at interception (m, m/s)
    q_f  = IK(x_f)                                          Drake InverseKinematics, joint limits on,
                                                            |f(q_f) − x_f|∞ ≤ ik_tolerance, seeded
                                                            from q(t0), cost |q_f − q(t0)|²
    v_f  = J⁺(q_f) ẋ_f                                      (rad/s; J⁺ damped, see below)
    q_d(t) = Σ_k c_k (t − t0)^k, k = 0..5                   quintic with q_d, v_d, a_d =
                                                            (q, v, 0) at t0 and (q_f, v_f, 0) at t1

For t ≥ t1 it follows the target by differential IK (k_x in 1/s; J⁺ is the damped
pseudoinverse Jᵀ(JJᵀ + λ²I)⁻¹, λ = pinv_damping, so a stretched arm gets bounded commands):

    v_d = J⁺(q) (ẋ_r + k_x (x_r − x)),  q_d = q,  a_d = J⁺(q) (ẍ_r + k_x (ẋ_r − ẋ) − J̇q̇)

[q_d, v_d, a_d] is tracked by Drake's stock ``InverseDynamicsController`` built on the
nominal plant:  τ = M̂(q)(a_d + kp (q_d − q) + kd (v_d − v) + ki ∫(q_d − q)) + Ĉ(q, v) v − ĝ(q),
with kp = ω², kd = 2ω (critically damped joint error, rad/s), ki from the config (default 0).
With an exact model the joint error obeys ë + 2ωė + ω²e = 0, so the arm is on the plan
and reaches x_f at t1 exactly when the prediction is exact; in the hold the task error
obeys ë + (k_x + 2ω) ė + 2ω k_x e = 0.  ω = 20 rad/s is well above the plan's bandwidth.

If IK finds no q_f within the tolerance (the predicted point is outside the workspace) the
plan goes to the target's present position x_r(t0) if reachable, else to the reachable point
nearest to x_f (``on_ik_failure = "nearest"``, the default: the run goes on, a miss is a
result, and the differential IK chases the target after t1; ``reached`` = 0 in the plan and
the telemetry), or the event raises ValueError naming the segment (``"raise"``).  The default
``predict`` (None) extrapolates the ``target`` input at constant acceleration:
x_f = x_r + ẋ_r Δ + ½ ẍ_r Δ², ẋ_f = ẋ_r + ẍ_r Δ, Δ = t1 − t0.
The quintic's coefficients live in the context's discrete state, not in Python attributes.

In the controller slot: ``ct_quintic``: a quintic joint plan tracked by inverse dynamics
(model-based reference).

It uses the *nominal* model (the model file without the scenario's plant deviations) and, for
analytic targets, their exact future.  Settings under
``controller.ct_quintic`` (``CtQuinticConfig``).
"""

from collections.abc import Callable

import numpy as np
from pydrake.multibody.inverse_kinematics import InverseKinematics
from pydrake.multibody.tree import JacobianWrtVariable
from pydrake.solvers import Solve
from pydrake.systems.controllers import InverseDynamicsController
from pydrake.systems.framework import Diagram, DiagramBuilder, LeafSystem
from pydrake.systems.primitives import Multiplexer

from ptint_drake.config.controller import CtQuinticConfig
from ptint_drake.controllers.baseline import layout_size, make_layout, segment_index
from ptint_drake.controllers.ptsmc.law import pinv_apply
from ptint_drake.controllers.slot import ControllerHandles, ControllerSlot, TargetView, telemetry_handles
from ptint_drake.systems.task.cache import DeclareVectorCache
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.schedule import DeclareSegmentStartEvents, Schedule
from ptint_drake.systems.task.signals import TARGET, TARGET_PORT_SIZE

Predictor = Callable[[int, float, np.ndarray], np.ndarray]


def quintic_coefficients(q0, v0, a0, qf, vf, af, T: float) -> np.ndarray:
    """c (6 × n) with q(s) = Σ c_k s^k meeting (q0, v0, a0) at s = 0 and (qf, vf, af) at s = T."""
    q0, v0, a0, qf, vf, af = (np.asarray(a, dtype=float) for a in (q0, v0, a0, qf, vf, af))
    h = qf - q0 - v0 * T - 0.5 * a0 * T**2
    dv = vf - v0 - a0 * T
    da = af - a0
    c3 = (10.0 * h - 4.0 * dv * T + 0.5 * da * T**2) / T**3
    c4 = (-15.0 * h + 7.0 * dv * T - da * T**2) / T**4
    c5 = (6.0 * h - 3.0 * dv * T + 0.5 * da * T**2) / T**5
    return np.stack([q0, v0, 0.5 * a0, c3, c4, c5])


def quintic_eval(c: np.ndarray, s: float):
    """(q, v, a) of the quintic with coefficients c (6 × n) at s."""
    p = s ** np.arange(6)
    k = np.arange(6)
    v_pow = np.concatenate([[0.0], k[1:] * p[:-1]])
    a_pow = np.concatenate([[0.0, 0.0], k[2:] * (k[2:] - 1) * p[:-2]])
    return p @ c, v_pow @ c, a_pow @ c


def constant_acceleration_predict(target: np.ndarray, dt: float) -> np.ndarray:
    """[x, ẋ] after dt (s) of a point moving with the constant acceleration of ``target``
    ([x_r, ẋ_r, ẍ_r]); the result's slots are ``TARGET.x`` and ``TARGET.xdot``."""
    x, v, a = target[TARGET.x], target[TARGET.xdot], target[TARGET.xddot]
    return np.concatenate([x + v * dt + 0.5 * a * dt * dt, v + a * dt])


def ct_reference_layout(nq: int) -> dict:
    """name -> slice of ``QuinticReference``'s telemetry (``tau`` is appended by the diagram).

    ``x_f``: the predicted interception point; ``reached``: 1 if the IK met it, 0 if the plan
    goes to the nearest reachable point; ``mode``: 0 on the quintic, 1 following after t1."""
    return make_layout([("x", 3), ("xdot", 3), ("e", 3), ("edot", 3), ("x_f", 3),
                        ("reached", 1), ("mode", 1), ("q_d", nq), ("v_d", nq), ("a_d", nq)])


class QuinticReference(LeafSystem):
    """Inputs ``state``, ``target``; outputs ``desired_state`` ([q_d; v_d]), ``desired_acceleration``
    (a_d) and ``telemetry``.  Discrete state: [segment, t0, t1, reached, x_f(3), q_f, v_f, c (6·nq)]."""

    def __init__(self, *, plant, frame, schedule: Schedule, config: CtQuinticConfig,
                 predict: Predictor | None = None):
        super().__init__()
        self._plant, self._frame = plant, frame
        self._schedule, self._config, self._predict = schedule, config, predict
        nq, nv = plant.num_positions(), plant.num_velocities()
        if nq != nv:
            raise ValueError(f"ct_quintic: needs nq == nv, got {nq}, {nv}")
        self._n = nq
        self._kinematics = FrameKinematics(plant, frame)
        self._bias_context = plant.CreateDefaultContext()
        self.layout = ct_reference_layout(nq)
        self._state_in = self.DeclareVectorInputPort("state", 2 * nq)
        self._target_in = self.DeclareVectorInputPort("target", TARGET_PORT_SIZE)
        self._plan_index = self.DeclareDiscreteState(np.concatenate([[-1.0], np.zeros(6 + 8 * nq)]))
        DeclareSegmentStartEvents(self, schedule, self._on_segment_start)
        deps = {self.time_ticket(), self.xd_ticket(), self.all_input_ports_ticket()}
        size = layout_size(self.layout)
        self._eval = DeclareVectorCache(self, "reference", size, self._calc, deps)
        L = self.layout
        qd, vd, ad = L["q_d"], L["v_d"], L["a_d"]
        self.DeclareVectorOutputPort(
            "desired_state", 2 * nq,
            lambda c, o: o.SetFromVector(np.concatenate([self._eval(c)[qd], self._eval(c)[vd]])),
            prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(
            "desired_acceleration", nq, lambda c, o: o.SetFromVector(self._eval(c)[ad]),
            prerequisites_of_calc=deps)
        self.DeclareVectorOutputPort(
            "telemetry", size, lambda c, o: o.SetFromVector(self._eval(c)), prerequisites_of_calc=deps)

    def plan(self, context) -> dict:
        """The stored plan: segment, t0, t1 (s), reached (IK met x_f), x_f (m), q_f (rad),
        v_f (rad/s), c (6 × nq)."""
        p, n = context.get_discrete_state(self._plan_index).value(), self._n
        return {"segment": int(p[0]), "t0": p[1], "t1": p[2], "reached": bool(p[3]), "x_f": p[4:7],
                "q_f": p[7:7 + n], "v_f": p[7 + n:7 + 2 * n], "c": p[7 + 2 * n:].reshape(6, n)}

    def _predicted(self, i: int, t0: float, t1: float, target: np.ndarray) -> np.ndarray:
        if self._predict is None:
            return constant_acceleration_predict(target, t1 - t0)
        return np.asarray(self._predict(i, t1, target), dtype=float)

    def _ik(self, x_f: np.ndarray, q_seed: np.ndarray):
        """q within ik_tolerance of x_f (joint limits on) nearest to q_seed, or None."""
        tol, plant = self._config.ik_tolerance, self._plant
        ik = InverseKinematics(plant, with_joint_limits=True)
        ik.AddPositionConstraint(self._frame, np.zeros(3), plant.world_frame(), x_f - tol, x_f + tol)
        ik.prog().AddQuadraticErrorCost(np.eye(self._n), q_seed, ik.q())
        ik.prog().SetInitialGuess(ik.q(), q_seed)
        result = Solve(ik.prog())
        return result.GetSolution(ik.q()) if result.is_success() else None

    def solve_ik(self, x_f: np.ndarray, q_seed: np.ndarray, segment: int,
                 x_now: np.ndarray | None = None) -> tuple:
        """(q_f, reached): q_f within ik_tolerance of x_f, nearest to q_seed (reached = True).

        When x_f is out of reach: ValueError naming the segment (``on_ik_failure = "raise"``), or
        (``"nearest"``) a pose at ``x_now`` (the target's position now) if that is reachable, else
        the pose within the joint limits whose frame is closest to x_f (reached = False).  The
        target's present position is preferred because the point closest to an unreachable one
        is on the workspace boundary, a singular stretched arm the differential IK cannot leave.
        """
        q_f = self._ik(x_f, q_seed)
        if q_f is not None:
            return q_f, True
        if self._config.on_ik_failure == "raise":
            raise ValueError(
                f"ct_quintic: segment {segment}: inverse kinematics found no joint position within "
                f"the joint limits for the predicted target {np.round(x_f, 4).tolist()} m")
        q_f = None if x_now is None else self._ik(x_now, q_seed)
        if q_f is not None:
            return q_f, False
        plant = self._plant
        nearest = InverseKinematics(plant, with_joint_limits=True)
        nearest.AddPositionCost(self._frame, np.zeros(3), plant.world_frame(), x_f, np.eye(3))
        nearest.prog().AddQuadraticErrorCost(1e-6 * np.eye(self._n), q_seed, nearest.q())
        nearest.prog().SetInitialGuess(nearest.q(), q_seed)
        result = Solve(nearest.prog())
        return (result.GetSolution(nearest.q()) if result.is_success() else q_seed.copy()), False

    def _on_segment_start(self, context, state) -> None:
        t0 = context.get_time()
        i = segment_index(self._schedule, t0)
        t1 = max(self._schedule[i].end, t0)
        qv = self._state_in.Eval(context)
        q0, v0 = qv[: self._n], qv[self._n:]
        target = self._target_in.Eval(context)
        goal = self._predicted(i, t0, t1, target)
        q_f, reached = self.solve_ik(goal[TARGET.x], q0, i, target[TARGET.x])
        _, _, J_f = self._kinematics.compute(q_f, np.zeros(self._n))
        v_f = pinv_apply(J_f, goal[TARGET.xdot], self._config.pinv_damping)
        zero = np.zeros(self._n)
        c = quintic_coefficients(q0, v0, zero, q_f, v_f, zero, t1 - t0) if t1 > t0 else \
            np.zeros((6, self._n))
        state.get_mutable_discrete_state(self._plan_index).SetFromVector(
            np.concatenate([[i, t0, t1, float(reached)], goal[TARGET.x], q_f, v_f, c.ravel()]))

    def _calc(self, context) -> np.ndarray:
        t = context.get_time()
        qv = self._state_in.Eval(context)
        target = self._target_in.Eval(context)
        q, v = qv[: self._n], qv[self._n:]
        x, xdot, J = self._kinematics.compute(q, v)
        plan = self.plan(context)
        if plan["segment"] >= 0 and t < plan["t1"]:
            mode = 0.0
            q_d, v_d, a_d = quintic_eval(plan["c"], t - plan["t0"])
        else:
            mode = 1.0
            q_d, v_d, a_d = self._follow(q, v, x, xdot, J, target)
        return np.concatenate([x, xdot, x - target[TARGET.x], xdot - target[TARGET.xdot], plan["x_f"],
                               [float(plan["reached"]), mode], q_d, v_d, a_d])

    def _follow(self, q, v, x, xdot, J, target):
        """Differential IK after t1: (q_d, v_d, a_d) = (q, J⁺(ẋ_r + k_x(x_r − x)), ...)."""
        k_x = self._config.k_x
        plant, pc = self._plant, self._bias_context
        plant.SetPositionsAndVelocities(pc, np.concatenate([q, v]))
        Jdot_v = plant.CalcBiasTranslationalAcceleration(
            pc, JacobianWrtVariable.kV, self._frame, np.zeros(3), plant.world_frame(),
            plant.world_frame()).ravel()
        lam = self._config.pinv_damping
        x_r, xdot_r = target[TARGET.x], target[TARGET.xdot]
        v_d = pinv_apply(J, xdot_r + k_x * (x_r - x), lam)
        a_d = pinv_apply(J, target[TARGET.xddot] + k_x * (xdot_r - xdot) - Jdot_v, lam)
        return q, v_d, a_d


class CtQuinticController(Diagram):
    """Inputs ``state`` (nq + nv), ``target`` ([x_r, ẋ_r, ẍ_r], ``signals.TARGET_PORT``); outputs
    ``u`` (nu), ``tau`` (nv) and ``telemetry`` (``layout``: the reference's slots, then ``tau``).

    A Diagram of ``QuinticReference`` and Drake's ``InverseDynamicsController`` (nominal plant).
    """

    def __init__(self, *, plant, frame, schedule: Schedule, config: CtQuinticConfig,
                 nominal_plant, predict: Predictor | None = None):
        super().__init__()
        config.validate()
        nv = plant.num_velocities()
        self.nominal_plant = nominal_plant  # the controller below keeps a reference to it
        builder = DiagramBuilder()
        ref = builder.AddNamedSystem("reference", QuinticReference(
            plant=plant, frame=frame, schedule=schedule, config=config, predict=predict))
        w = config.omega
        idc = builder.AddNamedSystem("inverse_dynamics", InverseDynamicsController(
            nominal_plant, kp=np.full(nv, w * w), ki=np.full(nv, config.ki), kd=np.full(nv, 2.0 * w),
            has_reference_acceleration=True))
        n_ref = layout_size(ref.layout)
        mux = builder.AddNamedSystem("telemetry", Multiplexer([n_ref, nv]))
        builder.ExportInput(ref.GetInputPort("state"), "state")
        builder.ConnectInput("state", idc.get_input_port_estimated_state())
        builder.ExportInput(ref.GetInputPort("target"), "target")
        builder.Connect(ref.GetOutputPort("desired_state"), idc.get_input_port_desired_state())
        builder.Connect(ref.GetOutputPort("desired_acceleration"),
                        idc.get_input_port_desired_acceleration())
        builder.Connect(ref.GetOutputPort("telemetry"), mux.get_input_port(0))
        builder.Connect(idc.get_output_port_generalized_force(), mux.get_input_port(1))
        builder.ExportOutput(idc.get_output_port_control(), "u")
        builder.ExportOutput(idc.get_output_port_generalized_force(), "tau")
        builder.ExportOutput(mux.get_output_port(0), "telemetry")
        builder.BuildInto(self)
        self.reference = ref
        self.inverse_dynamics = idc
        self.layout = dict(ref.layout, tau=slice(n_ref, n_ref + nv))

NAME = "ct_quintic"
SUMMARY = ("quintic joint plan to the target's future, tracked by inverse dynamics of the nominal "
           "model (model-based)")
CONFIG = CtQuinticConfig
MODEL_BASED = True


def AddCtQuintic(slot: ControllerSlot, config: CtQuinticConfig, target: TargetView) -> ControllerHandles:
    """Add the planner + inverse-dynamics tracker and wire it to the slot."""
    predict = None
    if target.analytic is not None:
        seen = target.analytic

        def predict(i, t1, _target, seen=seen):
            values = seen[i].evaluate(t1)
            return values[TARGET.x.start:TARGET.xdot.stop]
    system = slot.builder.AddNamedSystem("ct_quintic", CtQuinticController(
        plant=slot.plant, frame=slot.frame, schedule=slot.schedule, config=config,
        nominal_plant=slot.nominal_plant(), predict=predict))
    port = slot.connect(system, target)
    notes = [f"ct_quintic: inverse dynamics of the nominal model, ω = {config.omega:g} rad/s, "
             f"target future {'exact (analytic)' if predict else 'extrapolated from the estimate'}"]
    return telemetry_handles(NAME, system, port, notes)  # model-based: MODEL_BASED, read by the registry
