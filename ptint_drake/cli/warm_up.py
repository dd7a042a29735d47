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

import argparse
import multiprocessing
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Callable

import numpy as np

# scenario, ``--set`` overrides: each reaches kernels (or argument types) the others do not.  Two
# shares, run side by side (``warm_up``), that compile disjoint kernels: the position task's fused
# rows, the baselines and the blocks (which call the baselines' solve); the pose and top-down rows,
# the TBG, orientation and IMM kernels, then the camera runs (the IMM, and the position rows the
# other share has usually compiled by then: a process finds in numba's cache what another wrote;
# if not, both compile them, which costs time, not correctness).  Each share compiles what its own
# runs need first, so the two compile the same kernel only in that race.  Measured
# on a cold cache, 2 cores, nothing else running (2026-12-07, Python 3.13, Drake 1.58): in one
# process 148 CPU s; in two, shares dealt as before this order (the IMM in one share and a camera
# run needing it in the other, the baselines' solve and the blocks likewise), 101 s wall and
# 197 CPU s.
_RUNS = (
    (("curve_b075_tf15", []),
     ("conveyor_pair", ["controller.switching=sat", "controller.pinv_damping=0.01"]),
     ("curve_b075_tf15", ["controller.type=smc"]),
     ("curve_b075_tf15", ["controller.type=ct_quintic"]),  # pinv_solve (``ptint paper``'s comparisons)
     ("curve_b075_tf15", ["controller.implementation=blocks"])),
    (("curve_pose", []),
     None,  # the TBG, orientation and IMM kernels
     ("conveyor_yaw_camera", []),  # the top-down task from a filter, the orientation filter's output
     ("conveyor_pair_camera", []),
     ("throw_camera", [])),
)


def warm_up(duration: float = 0.05, report: Callable[[str], None] | None = None, workers: int = 2) -> float:
    """Simulate the first ``duration`` s of each of ``_RUNS`` (and recompute the fused system's
    telemetry of the last state, as a run's outputs do), then call the TBG, orientation and IMM
    kernels; the wall time in s.  ``report(line)`` gets a line per run (what compiled, how long it
    took): as each is done in one process, as each share is done in two.

    numba compiles on one core, so with ``workers`` = 2 the two shares of ``_RUNS`` (disjoint
    kernels) run side by side in two processes (``spawn``: a fresh interpreter each), compiling
    into the same cache (numba writes each entry to a temporary file and renames it into place);
    ``workers`` = 1 runs them one after the other here."""
    t0 = time.perf_counter()
    say = report or (lambda line: None)
    total = sum(len(share) for share in _RUNS)
    if workers <= 1:
        for i, line in enumerate((line for share in _RUNS for line in _compile(share, duration)), start=1):
            say(f"[{i}/{total}] {line}")
        return time.perf_counter() - t0
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        done = as_completed([pool.submit(_compile, share, duration) for share in _RUNS])
        lines = [line for future in done for line in future.result()]
    for i, line in enumerate(lines, start=1):
        say(f"[{i}/{total}] {line}")
    return time.perf_counter() - t0


def _compile(share, duration: float) -> list[str]:
    """Run each of ``share`` (a ``_RUNS`` entry: None is the TBG, orientation and IMM kernels) in
    this process (``warm_up``); a line per run: what it was and its wall time."""
    return [_run(run, duration) for run in share]


def _run(run, duration: float) -> str:
    """One entry of a share (``_compile``), simulated (or the kernels called); its line."""
    from ptint_drake.simulation import build, make_simulator  # noqa: PLC0415
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415
    from ptint_drake.systems.task.tbg import alpha_gain, alpha_peak, tbg_profile  # noqa: PLC0415

    t_run = time.perf_counter()
    if run is None:
        alpha_peak(1.5, 0.75)
        tbg_profile(0.5, 1.5, 0.75)
        xi, xi_dot, _, _ = tbg_profile(np.linspace(0.0, 1.5, 5), 1.5, 0.75)
        alpha_gain(xi, xi_dot)  # arrays, as ``figures.tbg_family_figure`` (``ptint paper``) calls it
        _orientation_kernels()
        _imm_kernels()
        return f"TBG, orientation and IMM kernels: {time.perf_counter() - t_run:.1f} s"
    name, overrides = run
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
    return f"{' '.join([name, *overrides])}: {time.perf_counter() - t_run:.1f} s"


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


def main(argv: list[str] | None = None) -> None:
    """``python -m ptint_drake.cli.warm_up [--workers N]`` (``scripts/setup.sh``)."""
    parser = argparse.ArgumentParser(prog="python -m ptint_drake.cli.warm_up",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, choices=(1, 2), default=2,
                        help="processes that compile side by side (2, the default: the two shares of "
                             "the runs; 1: one after the other, where another compile shares the cores)")
    workers = parser.parse_args(argv).workers
    runs = sum(run is not None for share in _RUNS for run in share)
    where = "in two processes" if workers == 2 else "in one process"
    _report(f"compiling (or loading from numba's cache) the kernels of {runs} short runs and the rest, "
            f"{where}; a few seconds when the cache is warm")
    wall = warm_up(report=_report, workers=workers)
    print(f"warm-up: compiled kernels ready in {wall:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
