"""Compile (or load from numba's cache) every compiled kernel once: ``python -m
ptint_drake.cli.warm_up`` (``scripts/setup.sh`` runs it after installing).

numba compiles a kernel at its first call for the argument types of that call and, with
``cache=True``, stores the machine code beside the module (or in ``NUMBA_CACHE_DIR``, or the
user's cache directory when the install is read-only).  Short runs of the bundled scenarios
exercise the kernels with the very types a ``ptint run`` passes: the fused position task with a
curve, a line and a thrown object, a target from a filter, the pose task (``pose_row``) and the
five blocks, the IMM of ``estimator: auto`` (``imm_kernels.imm_cycle``, ``initial_state``, in the
camera runs); then the orientation equations as the blocks and the metrics call them, and the
IMM's kernels once more directly (a cycle with a sample and one without).  The fused kernels'
general versions too (``InterceptorLaw.load_general_kernels``), which a run calls only where the
lean ones cannot solve (a singular J: ``controller.pinv_solve_into``); without the warm-up such a
run compiles them when it first needs them (``jit_notice``).
"""

from __future__ import annotations

import sys
import time
from typing import Callable

import numpy as np

# scenario, ``--set`` overrides: each reaches kernels (or argument types) the others do not
_RUNS = (
    ("curve_b075_tf15", []),
    ("curve_b075_tf15", ["controller.implementation=blocks"]),
    ("conveyor_pair", ["controller.switching=sat", "controller.pinv_damping=0.01"]),
    ("conveyor_pair_camera", []),
    ("throw_camera", []),
    ("curve_pose", []),
    ("conveyor_yaw_camera", []),  # the top-down task from a filter, the orientation filter's output
    ("curve_b075_tf15", ["controller.type=smc"]),
    ("curve_b075_tf15", ["controller.type=ct_quintic"]),  # pinv_solve (``ptint paper``'s comparisons)
)


def warm_up(duration: float = 0.05, report: Callable[[str], None] | None = None) -> float:
    """Simulate the first ``duration`` s of each of ``_RUNS`` (and recompute the fused system's
    telemetry of the last state, as a run's outputs do); the wall time in s.  ``report(line)``
    gets a line as each run and the last kernels are done (what compiled, how long it took)."""
    from ptint_drake.simulation import build, make_simulator  # noqa: PLC0415
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415
    from ptint_drake.systems.task.tbg import alpha_gain, alpha_peak, tbg_profile  # noqa: PLC0415

    say = report or (lambda line: None)
    t0 = time.perf_counter()
    steps = len(_RUNS) + 1
    for i, (name, overrides) in enumerate(_RUNS, start=1):
        t_run = time.perf_counter()
        _, text = scenario_text(name)
        scenario = parse_with_overrides(text, overrides, name)
        built = build(scenario, log=False)
        simulator = make_simulator(built)
        simulator.AdvanceTo(duration)
        law = getattr(built.controller.system, "law", None)
        system = built.controller.system
        if law is not None:
            law.load_general_kernels()
        if law is not None and not system.has_target_input and not system.has_rotation_input:
            context = law.GetMyContextFromRoot(simulator.get_context())
            qv, sigma, captured, _ = law.loop_values(context)
            system.telemetry_at([duration], qv[None], sigma[None], captured[None])
        say(f"[{i}/{steps}] {name}{' ' + ' '.join(overrides) if overrides else ''}: "
            f"{time.perf_counter() - t_run:.1f} s")
    t_rest = time.perf_counter()
    alpha_peak(1.5, 0.75)
    tbg_profile(0.5, 1.5, 0.75)
    xi, xi_dot, _, _ = tbg_profile(np.linspace(0.0, 1.5, 5), 1.5, 0.75)
    alpha_gain(xi, xi_dot)  # arrays, as ``figures.tbg_family_figure`` (``ptint paper``) calls it
    _orientation_kernels()
    _imm_kernels()
    say(f"[{steps}/{steps}] TBG, orientation and IMM kernels: {time.perf_counter() - t_rest:.1f} s")
    return time.perf_counter() - t0


def _orientation_kernels() -> None:
    """Call the compiled orientation equations as the blocks and a run's metrics call them (the
    fused pose kernel, ``interceptor_row.pose_row``, compiles in the ``curve_pose`` run)."""
    from ptint_drake.systems.task.error import task_error, task_jacobian, task_reference  # noqa: PLC0415
    from ptint_drake.systems.task.orientation import (  # noqa: PLC0415
        SpinningOrientation,
        orientation_error_angle,
        rotation_error,
        rotation_exp,
    )
    from ptint_drake.systems.task.signals import IDENTITY_ROTATION  # noqa: PLC0415

    R, w = rotation_exp([0.1, 0.2, 0.3]), [0.1, 0.0, 0.0]
    rot_r = SpinningOrientation([0.0, 0.0, 30.0], [0.0, 0.0, 10.0]).values(0.5)
    task_error("top_down", 0.1, *np.zeros((4, 3)), R, w, rot_r)
    rotation_error(R, w, task_reference("top_down", IDENTITY_ROTATION, R))
    orientation_error_angle("pose", R, rot_r)
    task_jacobian(np.zeros((3, 5)), np.zeros((3, 5)), 0.1)


def _imm_kernels() -> None:
    """Call the IMM's kernels with the argument types ``AdaptiveTargetEstimator.step`` passes."""
    from ptint_drake.systems.estimation.imm_kernels import NO_SAMPLE, imm_cycle, initial_state  # noqa: PLC0415

    z = np.array([0.3, 0.0, 0.2])
    X, Ps, mu = initial_state(z, 4.0e-6)
    for sample in (z, NO_SAMPLE):
        X, Ps, mu = imm_cycle(X, Ps, mu, 1.0 / 30.0, sample, 4.0e-6)


def _report(line: str) -> None:
    print(f"warm-up: {line}", file=sys.stderr, flush=True)


if __name__ == "__main__":
    _report(f"compiling (or loading from numba's cache) the kernels of {len(_RUNS)} short runs, then "
            f"the rest; a few seconds when the cache is warm")
    print(f"warm-up: compiled kernels ready in {warm_up(report=_report):.1f} s", file=sys.stderr)
