"""Warnings about a run: before it, whether the actuators can follow the prescribed time
(``torque_feasibility``) and whether sampled control is too slow (``sampled_control_warnings``);
after it, where the arm came near a singularity or went beyond its model's joint limits.  They
may use the model: the controller never sees them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np
from pydrake.multibody.plant import MultibodyPlant
from pydrake.multibody.tree import JacobianWrtVariable, MultibodyForces

from ptint_drake.config.schema import Scenario
from ptint_drake.robot.plant import effort_limits
from ptint_drake.robot.reachability import inverse_kinematics


def torque_feasibility(plant: MultibodyPlant, scenario: Scenario, targets: list,
                       samples: int = 200) -> list[str]:
    """Warnings for segments whose tf looks too short for the actuators' effort limits.

    A planning estimate (it uses the model, the controller does not): on the ideal
    surface the error follows e(t) ≈ e0 ξ(t), so the gripper needs the acceleration
    a(t) = ẍ_r(t) + e0 ξ̈(t).  ξ̈ is unbounded for β < 1/2; there the closed loop
    cannot follow it anyway and the β = 1/2 profile's bound is used.  The joint
    torque estimate is |M(q) J⁻¹ a| + |g(q)| at the segment's start and
    interception configurations and at every posture along its profile (``_profile``).  The
    acceleration part scales as 1/tf², which gives the suggested tf (``targets``: the
    interception world's objects).  e0 is taken from the start pose for the first segment and
    from the previous target for later ones.  The joint-speed term: |J⁺ẋ| along the same profile
    against the model's velocity limits (``feasibility_warning``, its own line).
    """
    from ptint_drake.systems.task.tbg import tbg_profile  # noqa: PLC0415

    frame = plant.GetFrameByName(scenario.robot.end_effector)
    context = plant.CreateDefaultContext()
    limits = effort_limits(plant)
    q_prev = np.radians(scenario.robot.initial_q_deg)
    plant.SetPositions(context, q_prev)
    x_prev = frame.CalcPoseInWorld(context).translation()
    warnings = []
    for i, ic in enumerate(scenario.interceptions):
        e0 = x_prev - targets[i].evaluate(ic.start)[0:3]
        tau = ic.tf * np.linspace(0.01, 0.99, samples)
        xi_dd = tbg_profile(tau, ic.tf, max(ic.beta, 0.5))[2]
        accelerations = [targets[i].evaluate(ic.start + s)[6:9] + e0 * xi_dd[k] for k, s in enumerate(tau)]
        x_end = targets[i].evaluate(ic.start + ic.tf)[0:3]
        q_end = inverse_kinematics(plant, frame, x_end, q_prev)
        profile = _profile(plant, frame, ic, targets[i], e0, q_prev)
        configs = [q_prev] + ([q_end] if q_end is not None else []) + (list(profile.q) if profile else [])
        need_acc, need_g = _torque_needed(plant, context, frame, configs, accelerations)
        warnings += [w for w in (_too_short(i, ic.tf, need_acc, need_g, limits),
                                 _speed_too_short(plant, frame, i, ic.tf, profile,
                                                  scenario.controller.pinv_damping)) if w]
        if q_end is not None:
            q_prev, x_prev = q_end, x_end
    return warnings


def _profile(plant: MultibodyPlant, frame, ic, target, e0: np.ndarray, q: np.ndarray) -> Optional[Profile]:
    """Interception ``ic``'s planned profile (position task): x = x_r + ξ e0, ẋ = ẋ_r + ξ̇ e0, the
    postures by inverse kinematics from sample to sample; None where one is not found
    (``check_reachable`` names an unreachable target)."""
    tau = profile_times(ic.tf)
    xi, xi_d = _xi_profile(tau, ic.tf, ic.beta)
    states = np.array([target.evaluate(ic.start + s) for s in tau])
    path = states[:, 0:3] + np.outer(xi, e0)
    postures = []
    for x in path:
        q = inverse_kinematics(plant, frame, x, q)
        if q is None:
            return None
        postures.append(q)
    velocity = states[:, 3:6] + np.outer(xi_d, e0)
    return Profile(ic.start + tau, np.array(postures), velocity, np.zeros_like(velocity))


def _speed_too_short(plant: MultibodyPlant, frame, i: int, tf: float, profile: Optional[Profile],
                     damping: float) -> Optional[str]:
    """The joint-speed term of interception i: |J⁺ẋ| (``joint_demand``) along its ``profile``."""
    if profile is None:
        return None
    speeds = joint_demand(plant, frame, profile, damping=damping)[0]
    none = np.zeros(plant.num_velocities())
    return feasibility_warning(f"interceptions[{i}].tf", tf, f"segment {i}", profile, speeds,
                               np.zeros_like(speeds), plant.GetVelocityUpperLimits(), none)


def _xi_profile(tau: np.ndarray, tf: float, beta: float) -> tuple[np.ndarray, np.ndarray]:
    """(ξ, ξ̇) of a segment at times τ since its start (``systems.task.tbg.tbg_profile``)."""
    from ptint_drake.systems.task.tbg import tbg_profile  # noqa: PLC0415

    return tuple(tbg_profile(tau, tf, beta)[0:2])


SAMPLED_CONTROL_WARNING_S = 0.002  # control periods from this one on get a warning


def sampled_control_warnings(scenario: Scenario) -> list[str]:
    """A warning when ``controller.control_period`` is 2 ms or longer: the held torque lags the
    sliding surface's fast boundary layer (measured on curve_b075_tf15, see ``controllers.hold``)."""
    period = scenario.controller.control_period
    if period < SAMPLED_CONTROL_WARNING_S:
        return []
    return [f"sampled control at {period * 1e3:g} ms: expect a hold error and chattering torques (paper "
            f"curve: 2 ms chatters at the torque limits and holds at 10 mm on a 2 ms discrete plant, 4 ms "
            f"misses with a 9 mm hold); 1 ms keeps its e(tf) at 0.07 mm, as continuous control does"]


def _torque_needed(plant: MultibodyPlant, context, frame, configs: list,
                   accelerations: list) -> tuple[np.ndarray, np.ndarray]:
    """Per joint, the largest |M(q) J⁺(q) a| over the configurations and accelerations and
    the largest |g(q)| over the configurations (at rest)."""
    need_acc = np.zeros(plant.num_velocities())
    need_g = np.zeros(plant.num_velocities())
    for q in configs:
        plant.SetPositions(context, q)
        plant.SetVelocities(context, np.zeros(plant.num_velocities()))
        M = plant.CalcMassMatrix(context)
        g = np.abs(plant.CalcGravityGeneralizedForces(context))
        J = plant.CalcJacobianTranslationalVelocity(
            context, JacobianWrtVariable.kV, frame, np.zeros(3), plant.world_frame(),
            plant.world_frame())
        Jp = np.linalg.pinv(J)
        for a in accelerations:
            need_acc = np.maximum(need_acc, np.abs(M @ (Jp @ a)))
        need_g = np.maximum(need_g, g)
    return need_acc, need_g


def _too_short(i: int, tf: float, need_acc: np.ndarray, need_g: np.ndarray,
               limits: np.ndarray) -> Optional[str]:
    """The warning for segment i when a joint needs more than its limit (None otherwise):
    the joint that exceeds it most, and the tf at which it would fit (need_acc ∝ 1/tf²)."""
    over = np.nonzero(need_acc + need_g > limits)[0]
    if not len(over):
        return None
    j = int(over[np.argmax((need_acc + need_g - limits)[over])])
    room = limits[j] - need_g[j]
    if room <= 0:
        hint = "gravity alone exceeds the limit there"
    else:
        hint = f"tf ≥ {tf * np.sqrt(need_acc[j] / room):.2f} s would fit"
    return (f"interceptions[{i}].tf = {tf:g} s looks too short for the actuators: joint "
            f"{j + 1} needs about {need_acc[j] + need_g[j]:.1f} N·m (limit {limits[j]:g} N·m); "
            f"{hint}")


def singularity_warnings(scenario: Scenario, series: dict) -> list:
    """A warning when J's smallest singular value (``series["sigma_min_J"]``, per logged step,
    from ``worlds.interception.series``) drops below ``limits.singular_value_warning``: when it
    first did, and the time and configuration where it was smallest."""
    threshold = scenario.limits.singular_value_warning
    if threshold <= 0 or len(series["t"]) == 0:
        return []
    smallest = series["sigma_min_J"]
    below = np.nonzero(smallest < threshold)[0]
    if len(below) == 0:
        return []
    k = int(np.argmin(smallest))
    deg = ", ".join(f"{v:.1f}" for v in np.degrees(series["q"][k]))
    damped = scenario.controller.pinv_damping
    advice = (f"the damped pseudoinverse (λ = {damped:g} m/rad) keeps the torques bounded" if damped
              else "consider controller.pinv_damping (e.g. 0.01) for a damped pseudoinverse")
    return [f"near-singular Jacobian from t = {series['t'][below[0]]:.3f} s; smallest singular value "
            f"{smallest[k]:.2e} m/rad (< {threshold:g}) at t = {series['t'][k]:.3f} s, q = ({deg}) deg; "
            f"{advice}"]


def joint_limit_warnings(plant: MultibodyPlant, series: dict) -> list[str]:
    """Warnings for joints that went beyond the model's position or speed limits during the
    run (a continuous plant does not enforce them): which joint, how far, and when."""
    warnings = []
    for kind, values, lower, upper, unit in (
            ("position", series["q"], plant.GetPositionLowerLimits(), plant.GetPositionUpperLimits(), "rad"),
            ("speed", series["v"], plant.GetVelocityLowerLimits(), plant.GetVelocityUpperLimits(), "rad/s")):
        for j in range(values.shape[1]):
            over = np.maximum(values[:, j] - upper[j], lower[j] - values[:, j])
            k = int(np.argmax(over))
            if len(over) and over[k] > 1e-9:
                first = float(series["t"][int(np.argmax(over > 1e-9))])
                limit = upper[j] if values[k, j] > upper[j] else lower[j]
                warnings.append(
                    f"joint {j + 1} {kind} {values[k, j]:.3g} {unit} at t = {series['t'][k]:.3f} s is "
                    f"beyond the model's limit {limit:.3g} {unit} (first beyond it at t = {first:.3f} s)")
    return warnings


# --- the feasibility model: what a planned profile asks of each joint ------------------------------

SPEED_SAMPLES = 21  # samples of each segment's profile, from PROFILE_START · tf to tf
# the ideal profile starts at the target's velocity (ė = ξ̇ e0 = 0) while the arm is at rest: its
# first 5 % are left out, as the metrics' peaks after start-up (``metrics.STARTUP_FRACTION``) do
PROFILE_START = 0.05


def profile_times(tf: float, samples: int = SPEED_SAMPLES) -> np.ndarray:
    """The times since a segment's start at which its profile is sampled (s): ``samples`` of them."""
    return tf * np.linspace(PROFILE_START, 1.0, samples)


@dataclass(frozen=True)
class Profile:
    """One segment's planned motion of the tool, sampled: per sample the time (s), the posture q
    (rad, from inverse kinematics), the task velocity and acceleration — [ω; v] and [α; a], 6 each,
    or [v] and [a], 3 each, for a position task — and the payload (kg) held at the tool."""

    t: np.ndarray
    q: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray
    payload: float = 0.0


def joint_demand(plant: MultibodyPlant, frame, profile: Profile, instance=None, rot_scale: float = 1.0,
                 damping: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(speeds, torques): the magnitudes of ``joint_terms``, each samples × joints."""
    speeds, torques = joint_terms(plant, frame, profile, instance, rot_scale, damping)
    return np.abs(speeds), np.abs(torques)


def joint_terms(plant: MultibodyPlant, frame, profile: Profile, instance=None, rot_scale: float = 1.0,
                damping: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(q̇, τ), signed, each samples × joints of ``instance`` (default: all of ``plant``):
    q̇ = J⁺ ẋ and q̈ = J⁺ (ẍ − J̇q̇) of the task's Jacobian (spatial for a 6-D task, translational
    for a 3-D one) at each posture, and τ = M q̈ + C q̇ − g (Drake's inverse dynamics, every body of
    ``plant``, e.g. a gripper welded to the arm) + Jᵥᵀ m (a − g) for a payload m held at the
    tool.  A 6-D task is weighed as the controller weighs it, [c ω; v] with c = ``rot_scale`` (m/rad),
    and inverted as it inverts it: J⁺, or Jᵀ(JJᵀ + λ²I)⁻¹ with λ = ``damping``
    (``controller.pinv_damping``: near a singularity the exact J⁺ would ask for speeds the damped
    controller never commands).  A planning estimate from the model: the controller never sees it."""
    motion = (profile.velocity, profile.acceleration)
    return joint_terms_of(plant, frame, profile.q, [motion], profile.payload, instance, rot_scale, damping)[0]


def joint_terms_of(plant: MultibodyPlant, frame, postures: np.ndarray, motions: list, payload: float = 0.0,
                   instance=None, rot_scale: float = 1.0, damping: float = 0.0) -> list:
    """``joint_terms`` of several motions of the tool on the same ``postures``: per motion
    (velocity, acceleration), samples × 6 or × 3 each, its (q̇, τ); one Jacobian and its inverse per
    posture for all of them."""
    context = plant.CreateDefaultContext()
    nv = plant.num_velocities()
    cols = (np.arange(nv) if instance is None
            else plant.GetVelocitiesFromArray(instance, np.arange(nv, dtype=float)).astype(int))
    six = motions[0][0].shape[1] == 6
    world = plant.world_frame()
    gravity = plant.gravity_field().gravity_vector()
    forces = MultibodyForces(plant)
    weight = np.r_[np.full(3, rot_scale), np.ones(3)] if six else np.ones(3)
    out = [(np.zeros((len(postures), len(cols))), np.zeros((len(postures), len(cols)))) for _ in motions]
    for k, q in enumerate(postures):
        _set_positions(plant, context, instance, q)
        plant.SetVelocities(context, np.zeros(nv))
        J, Jp = _task_jacobian(plant, context, frame, cols, weight, damping)
        for (velocity, acceleration), (speeds, torques) in zip(motions, out):
            xd, xdd = velocity[k], acceleration[k]
            v = np.zeros(nv)
            v[cols] = Jp @ (weight * xd)
            plant.SetVelocities(context, v)
            if six:
                bias = plant.CalcBiasSpatialAcceleration(context, JacobianWrtVariable.kV, frame, np.zeros(3),
                                                         world, world)
                bias = np.concatenate([bias.rotational(), bias.translational()])
            else:
                bias = plant.CalcBiasTranslationalAcceleration(context, JacobianWrtVariable.kV, frame,
                                                               np.zeros(3), world, world)[:, 0]
            vdot = np.zeros(nv)
            vdot[cols] = Jp @ (weight * (xdd - bias))
            forces.SetZero()
            tau = plant.CalcInverseDynamics(context, vdot, forces)[cols]
            if payload > 0.0:
                Jv = J[3:] if six else J  # (the translational rows: weight 1)
                tau = tau + Jv.T @ (payload * (xdd[-3:] - gravity))
            speeds[k], torques[k] = v[cols], tau
    return out


def loop_inertia(plant: MultibodyPlant, frame, postures: np.ndarray, payload: float = 0.0, instance=None,
                 rot_scale: float = 1.0, damping: float = 0.0) -> float:
    """kg·m² (per unit of the weighed task): the largest, over ``postures``, of 1 / λ_min(J M⁻¹ J⁺)
    — the controller's velocity loop τ = −K J⁺ s (eq. 18) on the arm of mass matrix M (the
    station's plant, plus ``payload`` kg held at the tool) closes as ṡ ≈ −K J M⁻¹ J⁺ s, so its
    slowest time constant is this over K.  J: the 6-D task Jacobian [ω; v] weighed by
    ``rot_scale`` and inverted as the controller inverts it (``damping``: ``joint_terms_of``);
    the eigenvalues of a direction J does not move (a 5-joint arm's sixth) are left out."""
    context = plant.CreateDefaultContext()
    nv = plant.num_velocities()
    cols = (np.arange(nv) if instance is None
            else plant.GetVelocitiesFromArray(instance, np.arange(nv, dtype=float)).astype(int))
    weight = np.r_[np.full(3, rot_scale), np.ones(3)]
    worst = 0.0
    for q in postures:
        _set_positions(plant, context, instance, q)
        M = plant.CalcMassMatrix(context)[np.ix_(cols, cols)]
        J, Jp = _task_jacobian(plant, context, frame, cols, weight, damping)
        if payload > 0.0:
            M = M + payload * J[3:].T @ J[3:]  # (the translational rows: weight 1)
        rates = np.linalg.eigvals(J @ np.linalg.solve(M, Jp)).real
        rates = rates[rates > 1e-9 * rates.max()]
        worst = max(worst, 1.0 / float(rates.min()))
    return worst


def _task_jacobian(plant: MultibodyPlant, context, frame, cols, weight: np.ndarray, damping: float) -> tuple:
    """(J, J⁺) at the context's posture: the task Jacobian of ``frame``'s origin — 6-D [ω; v] where
    ``weight`` has 6 entries, else 3-D v — on the velocity columns ``cols``, its rows weighed by
    ``weight``, and its pseudoinverse as the controller takes it (damped by ``damping`` > 0)."""
    world = plant.world_frame()
    if len(weight) == 6:
        J = plant.CalcJacobianSpatialVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3), world,
                                              world)[:, cols]
    else:
        J = plant.CalcJacobianTranslationalVelocity(context, JacobianWrtVariable.kV, frame, np.zeros(3),
                                                    world, world)[:, cols]
    J = weight[:, None] * J
    Jp = (np.linalg.pinv(J) if damping <= 0.0
          else J.T @ np.linalg.inv(J @ J.T + damping ** 2 * np.eye(len(J))))
    return J, Jp


def _set_positions(plant: MultibodyPlant, context, instance, q: np.ndarray) -> None:
    if instance is None:
        plant.SetPositions(context, q)
    else:
        plant.SetPositions(context, instance, q)


def feasibility_warning(field: str, tf: float, what: str, profile: Profile, speeds: np.ndarray,
                        torques: np.ndarray, speed_limits: np.ndarray,
                        effort_limits: np.ndarray) -> Optional[str]:
    """One line when a segment (``what``, e.g. "pick 1's via (segment 6)") asks a joint for more
    than its model's speed or effort limit somewhere along its planned ``profile`` (``speeds``,
    ``torques``: ``joint_demand``'s): the setting to change (``field`` = ``tf`` s), the joint and
    term with the largest ratio demand / limit, when, the other term's ratio if it is over too,
    and the ``field`` that would fit (the speeds scale as 1/tf, the torques, gravity aside, as
    1/tf²: a rough guide); None when every ratio ≤ 1."""
    with np.errstate(divide="ignore", invalid="ignore"):
        speed = np.where(speed_limits > 0, speeds / speed_limits, 0.0)
        torque = np.where(effort_limits > 0, torques / effort_limits, 0.0)
    worst_speed, worst_torque = float(np.max(speed, initial=0.0)), float(np.max(torque, initial=0.0))
    if max(worst_speed, worst_torque) <= 1.0:
        return None
    if worst_speed >= worst_torque:
        k, j = np.unravel_index(int(np.argmax(speed)), speed.shape)
        need = (f"joint {j + 1} at {worst_speed:.2f}× its speed limit ({speeds[k, j]:.3g} rad/s against "
                f"{speed_limits[j]:g} rad/s)")
        fit, other = tf * worst_speed, ("torque", worst_torque)
    else:
        k, j = np.unravel_index(int(np.argmax(torque)), torque.shape)
        need = (f"joint {j + 1} at {worst_torque:.2f}× its effort limit ({torques[k, j]:.3g} N·m against "
                f"{effort_limits[j]:g} N·m)")
        fit, other = tf * np.sqrt(worst_torque), ("speed", worst_speed)
    also = f", its {other[0]} {other[1]:.2f}×" if other[1] > 1.0 else ""
    return (f"{field} = {tf:g} s looks too short for the joints: {what} needs {need} at t = "
            f"{profile.t[k]:.2f} s{also}; {field} ≥ about {fit:.2f} s would fit")
