"""The catch world's flight model (issue 46): a ball in free flight with quadratic air drag,
p̈ = g − c |ṗ| ṗ (c = k / m, 1/m), its propagation, and its least-squares fit to camera samples.

``propagate(p, v, c, t0, times)``: the states [p, v] (6 per time) at ``times`` from [p, v] at
``t0``, forward or backward, by classical Runge–Kutta (RK4) in steps of at most ``H_MAX``
(compiled: numba).  At the 60 Hz sample spacing a step's error is ~1e-9 m on these flights
(the drag term is smooth and small: ≤ 3 % of g below 3.5 m/s).

``fit(ts, zs, sigma, guess)``: θ = [p, v, c] at the newest sample's time that minimises
Σ |p(t_k; θ) − z_k|² / σ² + ((c − C_PRIOR) / C_SIGMA)² over the samples (t_k, z_k), by
``scipy.optimize.least_squares`` (Levenberg–Marquardt, forward differences).  The drag is fitted,
not assumed: the prior is a broad one (C_PRIOR ± C_SIGMA covers a smooth sphere's to a rough
ball's drag, C_d 0.2–1.2, of any light 50–80 mm ball) that keeps c finite while the flight seen
is too short to show it; after ~0.3 s of flight the samples decide it (``tests/unit``).

``from_estimate``: the drag c read back from an estimate [p, v, a] with a = g − c|v|v, so that a
9-value estimate port carries the whole model (``catch_point`` and the planner use it).
"""

from __future__ import annotations

import numpy as np
from numba import njit
from scipy.optimize import least_squares

GRAVITY = np.array([0.0, 0.0, -9.81])
H_MAX = 0.02  # s, the longest RK4 step
C_PRIOR = 0.025  # 1/m: ½ ρ C_d A / m of a 65 mm, 40 g ball at C_d ≈ 0.5
C_SIGMA = 0.1  # 1/m


@njit(cache=True, inline="always")
def _deriv(v, c, out) -> None:
    s = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    out[0] = -c * s * v[0]
    out[1] = -c * s * v[1]
    out[2] = -9.81 - c * s * v[2]


@njit(cache=True)
def _rk4(p, v, c, h) -> None:
    """[p, v] advanced by one RK4 step of h (in place)."""
    a1, a2, a3, a4 = np.empty(3), np.empty(3), np.empty(3), np.empty(3)
    _deriv(v, c, a1)
    _deriv(v + 0.5 * h * a1, c, a2)
    _deriv(v + 0.5 * h * a2, c, a3)
    _deriv(v + h * a3, c, a4)
    v1, v2, v3 = v + 0.5 * h * a1, v + 0.5 * h * a2, v + h * a3
    p += h / 6.0 * (v + 2.0 * v1 + 2.0 * v2 + v3)
    v += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4)


@njit(cache=True)
def _sweep(p0, v0, c, t0, times, order, out) -> None:
    """Fill ``out[order[i]]`` with the state at ``times[order[i]]``, ``order`` sorted by the
    distance from t0 on one side of it."""
    p, v, t = p0.copy(), v0.copy(), t0
    for i in order:
        dt = times[i] - t
        n = max(1, int(np.ceil(abs(dt) / H_MAX - 1e-9)))
        for _ in range(n):
            _rk4(p, v, c, dt / n)
        t = times[i]
        out[i, 0:3] = p
        out[i, 3:6] = v


@njit(cache=True)
def _propagate(p, v, c, t0, times, out) -> None:
    order = np.argsort(times)
    ahead = order[times[order] >= t0]
    behind = order[times[order] < t0][::-1]
    _sweep(p, v, c, t0, times, ahead, out)
    _sweep(p, v, c, t0, times, behind, out)


def propagate(p, v, c: float, t0: float, times) -> np.ndarray:
    """States [p, v] (len(times) × 6) of the dragged flight through [p, v] at ``t0``."""
    times = np.atleast_1d(np.asarray(times, dtype=float))
    out = np.empty((len(times), 6))
    _propagate(np.asarray(p, float), np.asarray(v, float), float(c), float(t0), times, out)
    return out


def acceleration(v, c: float) -> np.ndarray:
    """g − c |v| v."""
    v = np.asarray(v, float)
    return GRAVITY - c * np.linalg.norm(v) * v


def from_estimate(estimate) -> float:
    """c of an estimate [p, v, a] whose a = g − c|v|v (the component of g − a along v); 0 at rest."""
    v, a = np.asarray(estimate[3:6], float), np.asarray(estimate[6:9], float)
    s = float(np.linalg.norm(v))
    return max(0.0, float(np.dot(GRAVITY - a, v)) / s ** 3) if s > 1e-6 else 0.0


def _residuals(theta, t_ref, ts, zs, sigma) -> np.ndarray:
    states = propagate(theta[0:3], theta[3:6], theta[6], t_ref, ts)
    r = (states[:, 0:3] - zs).ravel() / sigma
    return np.append(r, (theta[6] - C_PRIOR) / C_SIGMA)


def first_guess(ts, zs) -> np.ndarray:
    """θ from a drag-free least-squares line under gravity (linear) at the newest sample."""
    ts, zs = np.asarray(ts, float), np.asarray(zs, float)
    dt = ts - ts[-1]
    A = np.column_stack([np.ones_like(dt), dt])
    rhs = zs - 0.5 * np.outer(dt * dt, GRAVITY)
    (p, v), *_ = np.linalg.lstsq(A, rhs, rcond=None)
    return np.concatenate([p, v, [C_PRIOR]])


def fit(ts, zs, sigma: float, guess=None) -> np.ndarray:
    """θ = [p, v, c] at ``ts[-1]`` (module docstring); ``guess`` a θ at that time (else the
    drag-free line's).  At least 3 samples."""
    ts, zs = np.asarray(ts, float), np.asarray(zs, float)
    x0 = first_guess(ts, zs) if guess is None else np.asarray(guess, float)
    result = least_squares(_residuals, x0, args=(ts[-1], ts, zs, sigma), method="lm", x_scale="jac")
    theta = result.x
    theta[6] = max(theta[6], 0.0)
    return theta


def moved(theta, t_from: float, t_to: float) -> np.ndarray:
    """θ moved along its own flight from ``t_from`` to ``t_to`` (a warm start)."""
    state = propagate(theta[0:3], theta[3:6], theta[6], t_from, [t_to])[0]
    return np.concatenate([state, theta[6:7]])
