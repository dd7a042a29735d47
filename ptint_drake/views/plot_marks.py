"""Marks on a run figure's axes: a curve's peak (``peak_of``, ``peak_label``, ``mark_peak``) and a
y limit that shows the curves rather than one start-up spike (``robust_limit``).

``figures`` draws with them (and re-exports them); nothing here imports matplotlib.
"""

from __future__ import annotations

import numpy as np


def peak_of(t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(time, value) of the largest |y|."""
    k = int(np.argmax(np.abs(y)))
    return float(t[k]), float(y[k])


def peak_label(name: str, t_peak: float, value: float, unit: str) -> str:
    """``"τ1: peak −5.89 N·m at t = 0.178 s"`` (with a true minus sign, as on the axes)."""
    return f"{name}peak {value:.3g} {unit} at t = {t_peak:.3f} s".replace("-", "−")


def robust_limit(robot: np.ndarray, target: np.ndarray, spread: float = 3.0) -> float:
    """A symmetric y limit that shows the curves, not one start-up spike.

    The whole range when the robot's peak is within ``spread`` × its 99th percentile
    (and the target's range); otherwise the latter, and the peak is marked off scale.
    """
    robot, target = np.abs(robot), np.abs(target)
    whole = max(float(np.max(robot)), float(np.max(target)), 1e-12)
    body = max(float(np.percentile(robot, 99)), float(np.max(target)), 1e-12)
    return 1.08 * (whole if whole <= spread * body else body)


def mark_peak(ax, t_peak: float, value: float, limit: float | None = None, **style):
    """A marker at the peak; at the axis edge (pointing out) when it lies beyond ``limit``.
    Returns the marker's handle, for a legend."""
    off = limit is not None and abs(value) > limit
    y = np.sign(value) * limit if off else value
    marker = ("^" if value > 0 else "v") if off else "o"
    (h,) = ax.plot([t_peak], [y], ls="none", marker=marker, ms=6, mfc="none", mew=1.5,
                   clip_on=False, zorder=5, **style)
    return h
