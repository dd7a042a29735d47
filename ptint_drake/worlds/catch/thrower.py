"""The catch world's thrower: the frozen distribution of ``scripts/catch_oracle.py`` (issue 46),
drawn here the same way (``tests/unit/test_catch_world.py`` compares the two), from the ball's
numbers in ``ball``.

A throw leaves at t = 0 from a launch point 1.2–2.0 m from the arm's base (horizontally, within
±30° of +x, 0.7–1.3 m high) and passes, with drag, an aim point uniform in a 0.15 m ball about the
hand's start point 0.6–0.9 s later (``throw``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ptint_drake.worlds.catch.ball import BALL_MASS, drag_coefficient

GRAVITY = np.array([0.0, 0.0, -9.81])
LAUNCH_DISTANCE = (1.2, 2.0)
LAUNCH_AZIMUTH_DEG = (-30.0, 30.0)
LAUNCH_HEIGHT = (0.7, 1.3)
FLIGHT_TIME = (0.6, 0.9)
AIM_RADIUS = 0.15


@dataclass(frozen=True)
class Throw:
    """Launch point and velocity (m, m/s, world), aim point (m), flight time to it (s)."""

    seed: int
    launch: tuple
    velocity: tuple
    aim: tuple
    flight_time: float


def flight(p0, v0, t_end: float):
    """The dragged flight's dense solution (state [p; v]) from t = 0 to ``t_end``."""
    c = drag_coefficient() / BALL_MASS

    def rhs(_t, y):
        return np.concatenate([y[3:], GRAVITY - c * np.linalg.norm(y[3:]) * y[3:]])

    return solve_ivp(rhs, (0.0, t_end), np.concatenate([p0, v0]), rtol=1e-10, atol=1e-12,
                     dense_output=True).sol


def _shoot(p0, aim, T: float) -> np.ndarray:
    v0 = (aim - p0 - 0.5 * GRAVITY * T ** 2) / T
    for _ in range(8):
        v0 = v0 + (aim - flight(p0, v0, T)(T)[:3]) / T
    return v0


def throw(seed: int, hand_start: np.ndarray) -> Throw:
    """Throw ``seed`` aimed about ``hand_start`` (the module docstring's distribution)."""
    rng = np.random.default_rng([46, int(seed)])
    d = rng.uniform(*LAUNCH_DISTANCE)
    az = np.radians(rng.uniform(*LAUNCH_AZIMUTH_DEG))
    p0 = np.array([d * np.cos(az), d * np.sin(az), rng.uniform(*LAUNCH_HEIGHT)])
    T = rng.uniform(*FLIGHT_TIME)
    u = rng.normal(size=3)
    aim = np.asarray(hand_start) + AIM_RADIUS * np.cbrt(rng.uniform()) * u / np.linalg.norm(u)
    return Throw(int(seed), tuple(p0), tuple(_shoot(p0, aim, T)), tuple(aim), float(T))
