"""The interception world's time series: the per-step logs turned into arrays, measured from the
logged plant state and the true objects (never the controller's own view)."""

from __future__ import annotations

import numpy as np

from ptint_drake.systems.task.error import task_reference
from ptint_drake.systems.task.kinematics import FrameKinematics
from ptint_drake.systems.task.orientation import rotation_error, target_rotation_values
from ptint_drake.systems.task.targets import target_values


def collect_series(built, context, kinematics: FrameKinematics) -> dict:
    """The per-step logs as arrays: t, q, v, the controller's telemetry, the gripper point
    from the plant state with J's smallest singular value (``sigma_min_J``, m/rad, for
    ``run_warnings.singularity_warnings``), the true objects and the error against the active
    true target."""
    logs = {}
    for name, logger in built.loggers.items():
        log = logger.FindLog(context)
        logs[name] = log.data().T.copy()
        logs["t"] = log.sample_times().copy()
    t, state = logs["t"], logs["state"]
    plant, station = built.plant, built.station
    nq = plant.num_positions()
    series = dict(built.controller.telemetry(logs))
    series["t"] = t
    series["q"], series["v"] = state[:, :nq], state[:, nq:]
    x = np.empty((len(t), 3))
    xdot = np.empty((len(t), 3))
    redundant = plant.num_velocities() > 3
    self_motion = np.zeros(len(t))
    jacobians = np.empty((len(t), 3, plant.num_velocities()))
    for k in range(len(t)):
        v = state[k, nq:]
        x[k], xdot[k], J = kinematics.compute(state[k, :nq], v)
        jacobians[k] = J
        if redundant:  # |(I − J⁺J)(q − q_start)|: how far the arm wandered in its self-motion
            dq = state[k, :nq] - state[0, :nq]
            self_motion[k] = np.linalg.norm(dq - J.T @ np.linalg.solve(J @ J.T, J @ dq))
    series["x"], series["xdot"] = x, xdot
    series["sigma_min_J"] = np.linalg.svd(jacobians, compute_uv=False)[:, -1] if len(t) \
        else np.empty(0)  # J's smallest singular value (m/rad): how near a singularity
    if redundant:
        series["self_motion"] = self_motion
    targets = station.true_targets
    truth = np.array([[v for tg in targets for v in target_values(tg, tk)[0:6]]
                      for tk in t.tolist()], dtype=float).reshape(len(t), len(targets), 6)
    series["objects"] = truth[:, :, 0:3].reshape(len(t), -1)
    active = np.array([max(built.schedule.active(tk), 0) for tk in t], dtype=int)
    own = truth[np.arange(len(t)), active]
    series["e_true"] = x - own[:, 0:3]
    series["edot_true"] = xdot - own[:, 3:6]
    limits = station.effort_limits
    series["tau_applied"] = np.clip(series["tau"], -limits, limits) if station.saturate \
        else series["tau"].copy()
    return series


def orientation_series(task: str, kinematics: FrameKinematics, series: dict, targets, schedule,
                       duration: float) -> dict:
    """Per sample and per object i: the angle (deg) between the tool's orientation (forward
    kinematics of the logged plant state) and object i's TRUE orientation as the task asks for it
    (``rot_angle_deg``), and the rate of that error rotation |ω − R R_rᵀ ω_r| (``rot_rate_deg_s``),
    from segment i's start to the end of its hold (NaN elsewhere)."""
    t, q, v = series["t"], series["q"], series["v"]
    angle = np.full((len(t), len(targets)), np.nan)
    rate = np.full((len(t), len(targets)), np.nan)
    windows = [(seg.start, schedule.hold_end(i, duration)) for i, seg in enumerate(schedule.segments)]
    for k, tk in enumerate(t.tolist()):
        _, _, R, omega, _, _ = kinematics.compute_pose(q[k], v[k])
        for i, tg in enumerate(targets):
            if windows[i][0] <= tk <= windows[i][1]:
                reference = task_reference(task, target_rotation_values(tg, tk), R)
                e_R, edot_R = rotation_error(R, omega, reference)
                angle[k, i], rate[k, i] = np.linalg.norm(e_R), np.linalg.norm(edot_R)
    return {"rot_angle_deg": np.degrees(angle), "rot_rate_deg_s": np.degrees(rate)}
