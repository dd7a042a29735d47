"""What a run achieved and whether it intercepted: one definition for every command.

(No postponed annotations here: Drake's ``yaml_load_typed`` reads ``Criteria``'s field types.)

Everything here is measured against the *true* target from the plant's state
alone — the controller may have seen a measured or estimated target, and its
own telemetry is not trusted for the verdict.

The metrics of one segment (docs/results.md, docs/cli.md):

- ``e0_norm`` |e| at the segment start, ``e_half_norm`` at start + tf/2,
  ``e_tf_norm`` and ``edot_tf_norm`` at exactly start + tf (the simulator stops
  there), from the exact stops;
- ``e_hold_max_norm``: the largest |e| from start + tf to the next segment's
  start (or the end), last sample included;
- ``t_arrive``: the first time after the start at which |e| ≤ 1 mm (None if never).

The verdict (paper's prescribed-time property, docs/results.md):
a segment is ``late`` when |e(tf)| > ``criteria.e_tf``, ``early`` when it was
already closer than ``half_fraction`` |e0| at tf/2 (only when |e0| ≥ ``min_e0``:
a segment that starts on its target cannot arrive early), and ``hold`` when the
hold exceeds ``criteria.hold``.  A run is ``ok`` when every segment passes,
``missed`` otherwise, and ``failed`` when the divergence watchdog stopped it.
The reasons are ``Reason`` values (segment, code); metrics.json holds them printed
(``reasons``) and as data (``reason_codes``).
"""


import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ptint_drake.config.criteria import Criteria

ARRIVAL_TOLERANCE = 1.0e-3  # m: t_arrive is the first time |e| is within this
STARTUP_FRACTION = 0.05  # peaks "after start-up" skip the first 5 % of each segment's tf


def validate_criteria(c: Criteria) -> None:
    """ValueError naming the field of a criterion that is not a positive number."""
    for name in ("e_tf", "hold", "half_fraction", "min_e0", "e_rot_tf_deg", "rot_hold_deg", "min_e_rot0_deg",
                 "place_mm", "place_deg"):
        value = getattr(c, name)
        if not (math.isfinite(value) and value > 0.0):
            raise ValueError(f"criteria.{name}: must be > 0, got {value}")
    if c.half_fraction >= 1.0:
        raise ValueError(f"criteria.half_fraction: must be < 1, got {c.half_fraction}")


def segment_reasons(seg: dict, criteria: Criteria, margin: float = 1.0) -> list[str]:
    """The criteria a segment's metrics fail: a subset of ``late``, ``early``, ``hold``,
    ``orientation`` (a task with orientation: the angle at tf or in the hold too large; an angle
    that halved too soon is ``early`` too).

    ``margin`` M tightens the bounds to e_tf / M and hold / M (used by tuning).
    A segment the run never reached is ``late``.
    """
    if seg.get("e_tf_norm") is None:
        return ["late"]
    reasons = []
    if seg["e_tf_norm"] > criteria.e_tf / margin:
        reasons.append("late")
    e0, half = seg.get("e0_norm"), seg.get("e_half_norm")
    if e0 is not None and half is not None and e0 >= criteria.min_e0 and half < criteria.half_fraction * e0:
        reasons.append("early")
    if (seg.get("e_hold_max_norm") or 0.0) > criteria.hold / margin:
        reasons.append("hold")
    return reasons + _orientation_reasons(seg, criteria, margin, "early" in reasons)


def _orientation_reasons(seg: dict, criteria: Criteria, margin: float, early: bool) -> list[str]:
    """``orientation`` when the angle at tf or in the hold is beyond its bound; ``early`` when
    the angle was already below ``half_fraction`` of its start at tf/2 (not for ``position``)."""
    if seg.get("e_rot_tf_deg") is None:
        return []
    reasons = []
    r0, half = seg.get("e_rot0_deg"), seg.get("e_rot_half_deg")
    if not early and r0 is not None and half is not None and r0 >= criteria.min_e_rot0_deg \
            and half < criteria.half_fraction * r0:
        reasons.append("early")
    if seg["e_rot_tf_deg"] > criteria.e_rot_tf_deg / margin or \
            (seg.get("e_rot_hold_max_deg") or 0.0) > criteria.rot_hold_deg / margin:
        reasons.append("orientation")
    return reasons


@dataclass(frozen=True)
class Reason:
    """Why a run did not pass, as data: segment ``segment`` failed the criterion ``code``
    (``late``, ``early``, ``hold``, ``orientation``), or — ``segment`` None — the run ended without a verdict
    (``code`` ``failed``: the divergence watchdog; ``error``: it could not run) for the
    reason ``message``.  ``str()`` is the printed form (metrics.json's ``reasons``)."""

    segment: Optional[int]
    code: str
    message: str = ""

    def __str__(self) -> str:
        if self.segment is None:
            return self.message or self.code
        return f"segment {self.segment}: {self.code}"

    def as_dict(self) -> dict:
        """metrics.json's ``reason_codes`` entry: segment and code (and message, if any)."""
        out = {"segment": self.segment, "code": self.code}
        return out | ({"message": self.message} if self.message else {})

    @classmethod
    def from_dict(cls, data: dict) -> "Reason":
        return cls(data["segment"], data["code"], data.get("message", ""))


def verdict(metrics: dict, criteria: Criteria, margin: float = 1.0) -> tuple[str, list[Reason]]:
    """(status, reasons) of a run: ``ok``, ``missed`` (a ``Reason`` per failed criterion of
    each segment, printed ``segment 0: late``) or ``failed`` (the divergence watchdog stopped
    it; one ``Reason`` carrying its message)."""
    if metrics.get("failure"):
        return "failed", [Reason(None, "failed", metrics["failure"]["message"])]
    reasons = segments_reasons(metrics, criteria, margin)
    return ("missed" if reasons else "ok"), reasons


def segments_reasons(metrics: dict, criteria: Criteria, margin: float = 1.0) -> list[Reason]:
    """A ``Reason`` per failed criterion of each of ``metrics["segments"]``."""
    return [Reason(i, code) for i, seg in enumerate(metrics["segments"])
            for code in segment_reasons(seg, criteria, margin)]


def _peak(values: np.ndarray, t: np.ndarray, mask: Optional[np.ndarray] = None) -> dict:
    """Per-column peak of |values| and the time it happens (over ``mask`` rows if given)."""
    if mask is not None:
        values, t = values[mask], t[mask]
    if len(t) == 0:
        return {"value": [0.0] * values.shape[1], "time": [None] * values.shape[1]}
    k = np.argmax(np.abs(values), axis=0)
    cols = np.arange(values.shape[1])
    return {"value": np.abs(values[k, cols]).tolist(), "time": t[k].tolist()}


def after_startup(t: np.ndarray, segments) -> np.ndarray:
    """Rows outside the first ``STARTUP_FRACTION`` of every segment's tf: the peaks a
    sweep over tf should compare (at a segment start the surface is not zero because
    the object moves while the arm is at rest, so the first step dominates the peak)."""
    keep = np.ones(len(t), dtype=bool)
    for seg in segments:
        keep &= ~((t >= seg.start) & (t < seg.start + STARTUP_FRACTION * seg.tf))
    return keep


def segment_metrics(schedule, duration: float, samples: dict, t: np.ndarray, x: np.ndarray,
                    objects: np.ndarray) -> list[dict]:
    """Per-segment metrics from the exact stops (``samples``: time → (e, ė) against the
    true target active then) and the per-sample gripper point ``x`` (N × 3) and true object
    positions ``objects`` (N × 3·segments): segment i is measured against object i only,
    so its hold includes the instant the next segment starts."""
    rows = []
    for i, seg in enumerate(schedule.segments):
        t_end = schedule.hold_end(i, duration)
        e_norm = np.linalg.norm(x - objects[:, 3 * i:3 * i + 3], axis=1)
        row = {"start": seg.start, "tf": seg.tf, "beta": seg.beta, "hold_end": t_end}
        for key, at, which in (("e0_norm", seg.start, 0), ("e_half_norm", seg.start + 0.5 * seg.tf, 0),
                               ("e_tf_norm", seg.end, 0), ("edot_tf_norm", seg.end, 1)):
            row[key] = float(np.linalg.norm(samples[at][which])) if at in samples else None
        hold = (t >= seg.end) & (t <= t_end)
        if row["e_tf_norm"] is None:
            row["e_hold_max_norm"] = None
        else:
            row["e_hold_max_norm"] = max(float(np.max(e_norm[hold])) if hold.any() else 0.0,
                                         row["e_tf_norm"])
        inside = np.nonzero((t >= seg.start) & (t <= t_end) & (e_norm <= ARRIVAL_TOLERANCE))[0]
        row["t_arrive"] = float(t[inside[0]]) if len(inside) else None
        rows.append(row)
    return rows


ROTATION_KEYS = ("e_rot0_deg", "e_rot_half_deg", "e_rot_tf_deg", "e_rot_hold_max_deg", "edot_rot_tf_deg_s")


def rotation_metrics(schedule, duration: float, t: np.ndarray, angle: Optional[np.ndarray],
                     rate: Optional[np.ndarray]) -> list[dict]:
    """Per segment ``ROTATION_KEYS`` from the per-sample angle (deg, N × segments: the tool's
    orientation against object i's, as the task asks for it) and its rate (deg/s), at the exact
    stops (logged samples at start, start + tf/2, start + tf); all None without orientation."""
    rows = []
    for i, seg in enumerate(schedule.segments):
        if angle is None:
            rows.append(dict.fromkeys(ROTATION_KEYS))
            continue
        a, r = angle[:, i], rate[:, i]

        def at(time: float, values: np.ndarray):
            k = np.nonzero(t == time)[0]
            return float(values[k[-1]]) if len(k) else None

        hold = (t >= seg.end) & (t <= schedule.hold_end(i, duration))
        tf = at(seg.end, a)
        rows.append({"e_rot0_deg": at(seg.start, a), "e_rot_half_deg": at(seg.start + 0.5 * seg.tf, a),
                     "e_rot_tf_deg": tf, "e_rot_hold_max_deg": None if tf is None else max(
                         float(np.max(a[hold])) if hold.any() else 0.0, tf),
                     "edot_rot_tf_deg_s": at(seg.end, r)})
    return rows


def run_metrics(scenario, schedule, samples: dict, series: dict, limits: np.ndarray) -> dict:
    """The metrics of a run (docs/results.md): segments, torque and joint-speed peaks with
    their times, the peaks after start-up, and the fraction of time the actuators saturate.

    ``series`` holds ``t``, ``x`` (gripper point from the plant state), ``objects`` (true
    positions), ``v`` (joint speeds), ``tau`` (commanded) and ``tau_applied`` (saturated).
    """
    t = series["t"]
    segments = segment_metrics(schedule, scenario.duration, samples, t, series["x"], series["objects"])
    rotations = rotation_metrics(schedule, scenario.duration, t, series.get("rot_angle_deg"),
                                 series.get("rot_rate_deg_s"))
    for row, rot in zip(segments, rotations):
        row |= rot
    return {"scenario": scenario.name, "duration": scenario.duration, "segments": segments} | drive_metrics(
        schedule, t, series["tau"], series["tau_applied"], series["v"], limits) | {
        # redundant arms: the start posture's offset in the null space of J at the end (rad)
        "self_motion_final": float(series["self_motion"][-1]) if "self_motion" in series and len(t) else None}


def drive_metrics(schedule, t: np.ndarray, tau: np.ndarray, applied: np.ndarray, v: np.ndarray,
                  limits: np.ndarray) -> dict:
    """The drives' side of a run: torque peaks (applied) with their times, the same after each
    segment's start-up, the commanded peaks, joint-speed peaks, and the fraction of time any
    commanded torque exceeds its limit (``saturated_fraction``)."""
    over = np.any(np.abs(tau) > limits * (1.0 + 1e-9), axis=1)
    dt = np.diff(t, append=t[-1]) if len(t) else np.zeros(0)
    span = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    torque, torque_late = _peak(applied, t), _peak(applied, t, after_startup(t, schedule.segments))
    speed = _peak(v, t)
    return {
        "torque_peak": torque["value"],
        "torque_peak_time": torque["time"],
        "torque_peak_after_startup": torque_late["value"],
        "torque_peak_after_startup_time": torque_late["time"],
        "torque_command_peak": np.max(np.abs(tau), axis=0).tolist() if len(t) else [],
        "joint_speed_peak": speed["value"],
        "final_joint_speed": float(np.max(np.abs(v[-1]))) if len(t) else 0.0,
        "joint_speed_peak_time": speed["time"],
        "effort_limits": limits.tolist(),
        "saturated_fraction": float(np.sum(dt[over]) / span) if span > 0 else 0.0,
    }
