"""The commands that run many simulations, on worker processes or Dask: ``ptint sweep``, ``robust``,
``compare``, ``tune``, ``study camera`` (and ``--filter-floor``), ``bench``.

Each loads its scenario once (``options.scenario_and_out``) and hands the
``LoadedScenario`` to its study; the workers rebuild it from its text.  Option values arrive
checked by their argparse types (``cli.options``).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ptint_drake.cli.options import OptionError, out_folder, scenario_and_out


def _where(args: argparse.Namespace) -> dict:
    """--workers / --dask of a study as keyword arguments."""
    return {"workers": args.workers, "dask": args.dask}


def runs_progress(label: str, quiet: bool):
    """Progress of a study on stderr: one line per finished run."""
    if quiet:
        return None
    return lambda done, total, *_: print(f"{label}: {done}/{total} runs done", file=sys.stderr)


def _every_tenth(label: str, unit: str, quiet: bool):
    """Progress on stderr every 10 runs and at the end: ``LABEL: i/n UNIT``."""
    if quiet:
        return None
    return lambda i, n, *_: print(f"{label}: {i}/{n} {unit}", file=sys.stderr) \
        if i % 10 == 0 or i == n else None


def _dask_errors(call):
    from ptint_drake.studies.runner import SchedulerUnreachable  # noqa: PLC0415

    try:
        return call()
    except SchedulerUnreachable as exc:  # bad input: one line, exit 2
        raise OptionError(f"--dask: {exc}") from None


def cmd_sweep(args: argparse.Namespace) -> int:
    """The β × tf grid: sweep.csv and heat maps."""
    from ptint_drake.outputs.folder import staged_output  # noqa: PLC0415
    from ptint_drake.studies import sweep  # noqa: PLC0415

    loaded, out = scenario_and_out(args, "sweep_")
    rows = _dask_errors(lambda: sweep.run_sweep(loaded, args.beta, args.tf,
                                                progress=runs_progress("sweep", args.quiet), **_where(args)))
    with staged_output(out) as stage:  # entered only once every run finished
        sweep.heatmaps(rows, args.beta, args.tf, stage, f"{loaded.scenario.name}: β × tf sweep")
        sweep.write_csv(rows, stage / "sweep.csv")
    ok = sum(1 for r in rows if r.get("ok"))
    print(f"{len(rows)} runs, {ok} meet the prescribed-time property; wrote {out}/sweep.csv")
    return 0


def cmd_robust(args: argparse.Namespace) -> int:
    """The Monte Carlo study: robust.json, samples.json, worst.yaml, a histogram."""
    from ptint_drake.studies import robust  # noqa: PLC0415

    ranges = dict(robust.PRESETS[args.ranges]) | dict(args.range or [])
    loaded, out = scenario_and_out(args, "robust_")
    result = _dask_errors(lambda: robust.run_robust(
        loaded, args.samples, args.seed, ranges=ranges, preset=args.ranges,
        progress=_every_tenth("robust", "samples", args.quiet), **_where(args)))
    robust.write_robust(result, out)  # staged: the folder is created only now
    p = result["e_tf_percentiles"]
    print(f"{result['samples']} samples in {result['wall_time_s']:.1f} s "
          f"({result['samples_per_s']:.2f} samples/s), success rate {100 * result['success_rate']:.1f} %, "
          + (f"e(tf) p50 {p['p50'] * 1e3:.4f} mm, max {p['max'] * 1e3:.4f} mm; " if p else "")
          + f"worst seed {result['worst']['seed']}; wrote {out}/robust.json")
    if "pick_success_rate" in result:
        reasons = ", ".join(f"{k} ×{v}" for k, v in result["failures_by_reason"].items()) or "none"
        held = (f" ({100 * result['pick_success_rate_holdable']:.1f} % of those that can be held; "
                f"{result['cannot_be_held']} cannot)" if "cannot_be_held" in result else "")
        print(f"pick success rate {100 * result['pick_success_rate']:.1f} % of the parts{held}; "
              f"failures: {reasons}; placed with a collision: {result['placed_with_collision']}; "
              f"CPU {result['cpu_s_per_sample']['mean']:.1f} s a sample")
    return 0


def cmd_compare(args: argparse.Namespace) -> int:
    """Every controller × plant variant: compare.json/.csv/.md/.png and the table on stdout."""
    from ptint_drake.controllers import check_controller  # noqa: PLC0415
    from ptint_drake.simulation.scenario import check_variants  # noqa: PLC0415
    from ptint_drake.studies import compare  # noqa: PLC0415

    loaded, out = scenario_and_out(args, "compare_")
    check_variants(loaded.scenario, args.variants)  # a bad name fails before any run
    for controller in args.controllers:  # so does a plugin that cannot be used
        check_controller(compare.with_controller(loaded.scenario, controller))
    result = _dask_errors(lambda: compare.run_compare(
        loaded, args.controllers, args.variants, progress=runs_progress("compare", args.quiet),
        **_where(args)))
    compare.write_compare(result, out)
    print(compare.to_markdown(result))
    print(f"{compare.summary_line(result)}; wrote {out}/compare.md")
    return 0


def cmd_tune(args: argparse.Namespace) -> int:
    """The 1-D gain search: tuned.yaml (when a value works), tune.json, tune.png; exit 1 if none works."""
    from ptint_drake.studies import tune  # noqa: PLC0415

    loaded, out = scenario_and_out(args, "tune_")
    settings = tune.TuneSettings(gain=args.gain, variants=tuple(args.variants), margin=args.margin,
                                 max_saturation=args.max_saturation, bracket=args.range or ())
    say = (lambda message: None) if args.quiet else (lambda message: print(message, file=sys.stderr))
    result = _dask_errors(lambda: tune.run_tune(loaded, settings, progress=runs_progress("tune", args.quiet),
                                                say=say, **_where(args)))
    tune.write_tune(result, out)
    print(tune.summary_line(result))
    if result["gains"] is None:
        print(f"ptint: no tuned.yaml written; wrote {out}/tune.json, tune.png", file=sys.stderr)
        return 1
    print(f"wrote {out}/tuned.yaml (run it: ptint run {out}/tuned.yaml), tune.json, tune.png")
    return 0


def cmd_study(args: argparse.Namespace) -> int:
    """``study camera``: |e(tf)| over noise × latency × estimator, or ``--filter-floor``."""
    from ptint_drake.studies import camera  # noqa: PLC0415

    report = _every_tenth("study camera", "runs", args.quiet)
    if args.filter_floor:
        return _filter_floor(args, report)
    for flag, value in (("--scenario", args.scenario), ("--process-noise", args.process_noise),
                        ("--set", args.set)):
        if value is not None:
            raise OptionError(f"{flag}: only with --filter-floor")
    out = out_folder(args.out, Path("out") / f"study_{args.study}")
    result = camera.run_study(seeds=args.seeds, workers=args.workers, out=out, progress=report)
    runs = sum(row["summary"]["runs"] for row in result["table"])
    errors = sum(row["summary"]["errors"] for row in result["table"])
    print(f"{runs} runs ({errors} could not run) in {result['wall_time_s']:.0f} s with "
          f"{args.workers} workers; wrote {out}/camera_study.md, camera_study.json, estimate.png")
    return 0


def _filter_floor(args: argparse.Namespace, report) -> int:
    """``ptint study camera --filter-floor``: the camera + Kalman filter alone, per q and seed."""
    from ptint_drake.studies import filter_floor as floor  # noqa: PLC0415

    noises = args.process_noise if args.process_noise is not None else list(floor.FLOOR_PROCESS_NOISES)
    loaded, out = scenario_and_out(args, "filter_floor_", args.scenario or floor.FLOOR_SCENARIO)
    result = floor.filter_floor(loaded, noises, args.seeds, workers=args.workers, progress=report)
    floor.write_filter_floor(result, out)
    print(f"{floor.floor_summary_line(result)}; wrote {out}/filter_floor.md, filter_floor.json")
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """``ptint bench``: the benchmark's JSON on stdout, progress on stderr."""
    import json  # noqa: PLC0415

    from ptint_drake.studies import benchmark  # noqa: PLC0415

    result = benchmark.from_options(args, lambda step: print(f"bench: {step}", file=sys.stderr))
    print(json.dumps(result, indent=2))
    return 0
