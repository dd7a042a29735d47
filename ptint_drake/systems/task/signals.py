"""Named slots of the vectors the interceptor's blocks pass to each other — in one place.

Each layout maps a name to its index (a slot of size 1) or slice (a wider one), so code
reads ``target[TARGET.x]`` and ``tbg[TBG.alpha]`` instead of ``target[0:3]`` and ``tbg[4]``:

- ``TARGET``: [x_r, ẋ_r, ẍ_r, x⃛_r] of a target at time t (``evaluate(t)``, 12); a target
  *port* carries [x_r, ẋ_r, ẍ_r], the slots ``TARGET_PORT`` of width ``TARGET_PORT_SIZE``
  (the one place that width is written);
- ``TBG``: [ξ, ξ̇, ξ̈, ξ⃛, α, segment…] of ``tbg_state`` (paper eqs. 6–10, 13), 10;
- ``SEGMENT``: [index, t0, tf, β, phase] of the active segment (the TBG's ``segment`` port);
- ``CAPTURED``: [index, s(t0)], the surface's discrete state (paper eq. 17's s(t0));
- ``SURFACE``: [s_x, e, ė, s, s_d, σ̇] of ``SurfaceLaw`` (paper eqs. 11, 16, 17), 18, for the
  3-D position task; ``surface_slots(n)`` / ``captured_slots(n)`` for a task of dimension n
  (6 for the ``pose`` and ``top_down`` tasks: [position; rot_scale · rotation]);
- ``TARGET_ROTATION``: [R_r (row-major), ω_r, ω̇_r] of a target's orientation at t (15): what a
  ``target_rotation`` port carries (``TARGET_ROTATION_SIZE``).
"""

from __future__ import annotations


class Slots:
    """Names → index (size 1) or slice (size > 1) of a flat vector; ``size`` is its length."""

    def __init__(self, *fields: tuple[str, int]):
        lo = 0
        self.names = []
        for name, n in fields:
            setattr(self, name, lo if n == 1 else slice(lo, lo + n))
            self.names.append(name)
            lo += n
        self.size = lo

    def slices(self) -> dict:
        """name → slice (size-1 slots too), e.g. for splitting logged columns."""
        return {name: (slice(v, v + 1) if isinstance(v, int) else v)
                for name, v in ((n, getattr(self, n)) for n in self.names)}


TARGET = Slots(("x", 3), ("xdot", 3), ("xddot", 3), ("xdddot", 3))
TARGET_PORT = slice(0, TARGET.xddot.stop)  # what a target port carries: [x_r, ẋ_r, ẍ_r]
TARGET_PORT_SIZE = TARGET_PORT.stop  # 9: the width of every ``target`` port
TBG = Slots(("xi", 1), ("xi_dot", 1), ("xi_ddot", 1), ("xi_dddot", 1), ("alpha", 1), ("segment", 5))
TBG_PROFILE = slice(0, 4)  # [ξ, ξ̇, ξ̈, ξ⃛]
TBG_OUT = slice(0, 5)  # [ξ, ξ̇, ξ̈, ξ⃛, α]: the TBG's part of the telemetry
SEGMENT = Slots(("index", 1), ("t0", 1), ("tf", 1), ("beta", 1), ("phase", 1))


def captured_slots(n: int) -> Slots:
    """[index, s(t0)] of a task of dimension n."""
    return Slots(("index", 1), ("s0", n))


def surface_slots(n: int) -> Slots:
    """[s_x, e, ė, s, s_d, σ̇] of a task of dimension n; ``out`` = the telemetry part [s_x … s_d]."""
    slots = Slots(("s_x", n), ("e", n), ("edot", n), ("s", n), ("s_d", n), ("sigma_dot", n))
    slots.out = slice(0, 5 * n)
    return slots


CAPTURED = captured_slots(3)
SURFACE = surface_slots(3)
SURFACE_OUT = SURFACE.out  # [s_x, e, ė, s, s_d]: the surface's part of the telemetry
TARGET_ROTATION = Slots(("R", 9), ("omega", 3), ("omega_dot", 3))
TARGET_ROTATION_SIZE = TARGET_ROTATION.size  # 15: the width of every ``target_rotation`` port
IDENTITY_ROTATION = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0) + (0.0,) * 6  # a fixed, unturned object
