"""ptint: prescribed-time interception of moving objects with a robot arm (Drake).

    ptint list                              bundled scenarios
    ptint run NAME_OR_FILE [--out DIR]      one scenario: metrics.json, series.npz, figures, replay.html
    ptint paper [--out DIR]                 every paper scenario + TBG figures + index.html
    ptint diagram NAME_OR_FILE [--out DIR]  the built diagram as Graphviz .dot and .svg
    ptint sweep NAME_OR_FILE --beta B,.. --tf T,.. [--workers N | --dask ADDRESS] [--out DIR]
                                            grid → sweep.csv
    ptint robust NAME_OR_FILE --samples N [--seed S] [--workers W | --dask ADDRESS] [--out DIR]
                                            Monte Carlo
    ptint bench [SCENARIO ...]              speed and accuracy benchmark, JSON on stdout

``--set key=value`` (repeatable) overrides any scenario field, list items
included, e.g. ``--set controller.switching=sign --set 'interceptions[0].tf=1.2'``;
values are YAML.  Bad input ends with one line ``ptint: error: FIELD: ...`` and exit 2.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path

from ptint_drake.scenario import ScenarioError, bundled_scenarios, scenario_text

_PATH_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]|(\.)")


def _split_path(key: str) -> list:
    """``interceptions[1].target.linear.velocity`` → ``['interceptions', 1, 'target', ...]``."""
    parts, pos, expect_name = [], 0, True
    while pos < len(key):
        m = _PATH_TOKEN.match(key, pos)
        if m is None or (m.group(1) and not expect_name) or (m.group(2) and expect_name) \
                or (m.group(3) and expect_name):
            raise ScenarioError(f"--set {key}: not a field path (expected e.g. "
                                f"controller.K or interceptions[0].tf)")
        if m.group(1):
            parts.append(m.group(1))
        elif m.group(2):
            parts.append(int(m.group(2)))
        expect_name = bool(m.group(3))
        pos = m.end()
    if not parts or expect_name:
        raise ScenarioError(f"--set {key}: not a field path (expected e.g. "
                            f"controller.K or interceptions[0].tf)")
    return parts


def _path_text(parts) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else p)
                   for i, p in enumerate(parts))


def _apply_override(tree: dict, key: str, value) -> None:
    """Set ``value`` at the path ``key`` (dots and ``[i]``) in the plain YAML data ``tree``."""
    parts = _split_path(key)
    node = tree
    for depth, part in enumerate(parts):
        here = _path_text(parts[:depth]) or "the scenario"
        last = depth == len(parts) - 1
        if isinstance(part, int):
            if not isinstance(node, list):
                raise ScenarioError(f"--set {key}: {here} is not a list, it cannot be indexed")
            if part >= len(node):
                raise ScenarioError(f"--set {key}: index {part} out of range ({here} has "
                                    f"{len(node)} item{'s' if len(node) != 1 else ''})")
        elif not isinstance(node, dict):
            kind = "a list (use [i])" if isinstance(node, list) else f"not a mapping ({node!r})"
            raise ScenarioError(f"--set {key}: {here} is {kind}")
        if last:
            node[part] = value
        else:
            if isinstance(part, str) and node.get(part) is None:
                node[part] = [] if isinstance(parts[depth + 1], int) else {}
            node = node[part]


def _yaml_loader():
    """PyYAML's safe loader that also reads ``1e-6`` as a number (YAML 1.2, as Drake does)."""
    import yaml  # noqa: PLC0415

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver(
        "tag:yaml.org,2002:float", re.compile(r"^[-+]?(?:[0-9][0-9_]*)?(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
        list("-+0123456789."))
    return Loader


def override_text(text: str, overrides) -> str:
    """The scenario YAML ``text`` with each ``key=value`` of ``overrides`` applied.

    Keys are paths with dots and list indices (``interceptions[0].target.linear.start``);
    values are YAML.  Field names are not checked here: ``parse_scenario`` reports
    unknown ones with their path.
    """
    import yaml  # noqa: PLC0415  (PyYAML ships with drake's dependencies)

    if not overrides:
        return text
    loader = _yaml_loader()
    try:
        tree = yaml.load(text, Loader=loader)  # noqa: S506  (a SafeLoader subclass)
    except yaml.YAMLError:
        return text  # parse_scenario reports where the file is malformed
    if tree is None:
        tree = {}
    if not isinstance(tree, dict):
        return text  # parse_scenario reports "expected a mapping"
    for pair in overrides:
        if "=" not in pair:
            raise ScenarioError(f"--set: expected key=value, got {pair!r}")
        key, raw = (v.strip() for v in pair.split("=", 1))
        try:
            value = yaml.load(raw, Loader=loader)  # noqa: S506
        except yaml.YAMLError:
            raise ScenarioError(f"--set {key}: value {raw!r} is not valid YAML") from None
        _apply_override(tree, key, value)
    return yaml.safe_dump(tree, sort_keys=False)


def load_text(name_or_file: str, overrides=None) -> tuple[str, str]:
    """(name, YAML text) of a scenario with the ``--set`` overrides applied."""
    name, text = scenario_text(name_or_file)
    return name, override_text(text, overrides)


def load(name_or_file: str, overrides=None):
    """The validated scenario ``name_or_file`` with the ``--set`` overrides applied."""
    from ptint_drake.scenario import parse_scenario  # noqa: PLC0415

    name, text = scenario_text(name_or_file)
    if not overrides:
        return parse_scenario(text, name)
    changed = override_text(text, overrides)
    try:
        return parse_scenario(changed, name)
    except ScenarioError as exc:
        parse_scenario(text, name)  # an error of the file itself is reported as such
        raise ScenarioError(f"--set: {exc}") from None


def _out_dir(value, default: Path) -> Path:
    """The ``--out`` folder; a one-line error if it (or a parent) is an existing file."""
    out = Path(value) if value else default
    for p in (out, *out.parents):
        if p.exists():
            if not p.is_dir():
                raise ScenarioError(f"--out: {p} is a file" if p == out
                                    else f"--out: {p} (in {out}) is a file")
            break
    return out


def _progress(label: str):
    """Progress on stderr: a bar redrawn in place on a terminal; otherwise (a log file,
    a pipe) one line per 10 % of simulated time.  The returned ``report(t, duration,
    steps=None)`` adds the integrator's step count when the caller passes it."""
    tty = sys.stderr.isatty()
    printed = [-1]  # the last tenth reported (non-tty)

    def report(t, duration, steps=None):
        frac = min(t / duration, 1.0) if duration > 0 else 1.0
        extra = f", {steps} steps" if steps is not None else ""
        if not tty:
            tenth = int(frac * 10 + 1e-9)
            if tenth <= printed[0]:
                return
            printed[0] = tenth
            sys.stderr.write(f"{label}: {10 * tenth:3d} % ({t:.2f}/{duration:.2f} s simulated"
                             f"{extra})\n")
            sys.stderr.flush()
            return
        width = 30
        done = int(width * frac)
        end = "\n" if t >= duration else ""
        sys.stderr.write(f"\r{label:<18} [{'#' * done}{'.' * (width - done)}] "
                         f"{t:5.2f}/{duration:.2f} s simulated{extra}{end}")
        sys.stderr.flush()
    return report


def cmd_list(args) -> int:
    for name in bundled_scenarios():
        _, text = scenario_text(name)
        first = text.splitlines()[0].lstrip("# ").strip() if text.startswith("#") else ""
        print(f"{name:<18} {first}")
    return 0


def _mm(value) -> str:
    return "n/a" if value is None else f"{value * 1e3:.4g} mm"


def _segment_line(name: str, i: int, seg: dict, criteria) -> str:
    from ptint_drake.metrics import segment_reasons  # noqa: PLC0415

    reasons = segment_reasons(seg, criteria)
    return (f"{name} segment {i}: e0 = {_mm(seg['e0_norm'])}, e(tf/2) = {_mm(seg['e_half_norm'])}, "
            f"e(tf) = {_mm(seg['e_tf_norm'])}, hold max = {_mm(seg['e_hold_max_norm'])}: "
            + (f"MISSED ({', '.join(reasons)})" if reasons else "ok"))


def cmd_run(args) -> int:
    from ptint_drake.run_outputs import run_and_write  # noqa: PLC0415

    _out_dir(args.out, Path("out"))  # an --out that is a file fails before the run
    scenario = load(args.scenario, args.set)
    out = _out_dir(args.out, Path("out") / scenario.name)
    warn = lambda message: print(f"ptint: warning: {message}", file=sys.stderr)  # noqa: E731
    metrics = run_and_write(scenario, out, replay=not args.no_replay,
                            figures=not args.no_figures,
                            progress=None if args.quiet else _progress(scenario.name), warn=warn)
    for note in metrics["controller"]["notes"]:
        print(note)
    for i, seg in enumerate(metrics["segments"]):
        print(_segment_line(scenario.name, i, seg, scenario.criteria))
    sim = metrics["sim"]
    print(f"realtime factor {sim['realtime_factor']:.2f} end to end, {sim['steps']} steps, "
          f"{sim['derivative_evaluations']} derivative evaluations, saturated "
          f"{100 * metrics['saturated_fraction']:.1f} % of the time; wrote {out}/")
    for message in metrics["warnings"][metrics["warnings_before_run"]:]:
        warn(message)
    if metrics["status"] == "failed":
        print(f"ptint: error: run failed: {metrics['failure']['message']} "
              f"(outputs up to then are in {out}/, metrics.json says status: failed)", file=sys.stderr)
        return 1
    if metrics["status"] == "missed":
        print(f"{scenario.name}: MISSED ({'; '.join(metrics['reasons'])}); the gains may not fit "
              f"this arm or tf: try `ptint tune {args.scenario}`")
        return 1
    print(f"{scenario.name}: ok (every segment meets the criteria)")
    return 0


def cmd_diagram(args) -> int:
    from ptint_drake.run_outputs import write_diagram  # noqa: PLC0415

    scenario = load(args.scenario, args.set)
    out = _out_dir(args.out, Path("out") / scenario.name)
    paths = write_diagram(scenario, out)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_paper(args) -> int:
    from ptint_drake.paper_report import write_paper  # noqa: PLC0415

    index = write_paper(_out_dir(args.out, Path("out/paper")),
                        progress_factory=None if args.quiet else _progress)
    print(f"wrote {index}")
    return 0


def _floats(text: str, flag: str) -> list:
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ScenarioError(f"{flag}: expected comma-separated numbers, got {text!r}") from None
    if not values:
        raise ScenarioError(f"{flag}: no values given")
    return values


def _where(args):
    """--workers / --dask of a study, checked."""
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers: must be >= 1, got {args.workers}")
    return {"workers": args.workers, "dask": args.dask}


def _runs(label: str, quiet: bool):
    """Progress of a study on stderr: one line per finished run."""
    if quiet:
        return None
    return lambda done, total, *_: print(f"{label}: {done}/{total} runs done", file=sys.stderr)


def _dask_errors(call):
    from ptint_drake.studies.runner import SchedulerUnreachable  # noqa: PLC0415

    try:
        return call()
    except SchedulerUnreachable as exc:  # bad input: one line, exit 2
        raise ScenarioError(f"--dask: {exc}") from None


def cmd_sweep(args) -> int:
    from ptint_drake.outputs import staged_output  # noqa: PLC0415
    from ptint_drake.studies import sweep  # noqa: PLC0415

    betas, tfs = _floats(args.beta, "--beta"), _floats(args.tf, "--tf")
    for b in betas:
        if not 0.0 < b < 1.0:
            raise ScenarioError(f"--beta: every value must be in (0, 1), got {b}")
    for tf in tfs:
        if not tf > 0.0:
            raise ScenarioError(f"--tf: every value must be > 0, got {tf}")
    where = _where(args)
    _out_dir(args.out, Path("out"))
    scenario = load(args.scenario, args.set)  # validates the base scenario before any worker starts
    name, text = load_text(args.scenario, args.set)
    out = _out_dir(args.out, Path("out") / f"sweep_{scenario.name}")
    rows = _dask_errors(lambda: sweep.run_sweep(text, name, betas, tfs, progress=_runs("sweep", args.quiet),
                                                **where))
    with staged_output(out) as stage:  # entered only once every run finished
        sweep.heatmaps(rows, betas, tfs, stage, f"{scenario.name}: β × tf sweep")
        sweep.write_csv(rows, stage / "sweep.csv")
    ok = sum(1 for r in rows if r.get("ok"))
    print(f"{len(rows)} runs, {ok} meet the prescribed-time property; wrote {out}/sweep.csv")
    return 0


def cmd_robust(args) -> int:
    from ptint_drake.studies import robust  # noqa: PLC0415

    if args.samples < 1:
        raise ScenarioError(f"--samples: must be >= 1, got {args.samples}")
    where = _where(args)
    ranges = dict(robust.RANGES)
    for pair in args.range or []:
        key, _, value = pair.partition("=")
        if key not in ranges:
            raise ScenarioError(f"--range: unknown parameter {key!r} (one of {', '.join(ranges)})")
        lo_hi = _floats(value, f"--range {key}")
        if len(lo_hi) != 2 or lo_hi[0] > lo_hi[1] or lo_hi[0] < 0:
            raise ScenarioError(f"--range {key}: expected LOW,HIGH with 0 <= LOW <= HIGH, got {value!r}")
        ranges[key] = tuple(lo_hi)
    _out_dir(args.out, Path("out"))
    scenario = load(args.scenario, args.set)
    name, text = load_text(args.scenario, args.set)
    out = _out_dir(args.out, Path("out") / f"robust_{scenario.name}")
    report = None if args.quiet else (
        lambda i, n: print(f"robust: {i}/{n} samples", file=sys.stderr) if i % 10 == 0 or i == n else None)
    result = _dask_errors(lambda: robust.run_robust(text, name, args.samples, args.seed, ranges=ranges,
                                                    progress=report, **where))
    robust.write_robust(result, out)  # staged: the folder is created only now
    p = result["e_tf_percentiles"]
    print(f"{result['samples']} samples in {result['wall_time_s']:.1f} s "
          f"({result['samples_per_s']:.2f} samples/s), success rate {100 * result['success_rate']:.1f} %, "
          f"e(tf) p50 {p.get('p50', float('nan')) * 1e3:.4f} mm, "
          f"max {p.get('max', float('nan')) * 1e3:.4f} mm; "
          f"worst seed {result['worst']['seed']}; wrote {out}/robust.json")
    return 0


def cmd_compare(args) -> int:
    from ptint_drake.controllers import check_controller  # noqa: PLC0415
    from ptint_drake.scenario import check_variants  # noqa: PLC0415
    from ptint_drake.studies import compare  # noqa: PLC0415

    controllers = compare.controller_list(args.controllers)
    variants = compare.parse_list(args.variants, "--variants")
    where = _where(args)
    _out_dir(args.out, Path("out"))
    scenario = load(args.scenario, args.set)
    name, text = load_text(args.scenario, args.set)
    check_variants(scenario, variants)  # a bad name fails before any run
    for controller in controllers:  # a plugin that cannot be used fails before any run
        check_controller(compare.with_controller(scenario, controller))
    out = _out_dir(args.out, Path("out") / f"compare_{scenario.name}")
    result = _dask_errors(lambda: compare.run_compare(
        text, name, controllers, variants, progress=_runs("compare", args.quiet), **where))
    compare.write_compare(result, out)
    print(compare.to_markdown(result))
    print(f"{compare.summary_line(result)}; wrote {out}/compare.md")
    return 0


def cmd_tune(args) -> int:
    from ptint_drake.studies import tune  # noqa: PLC0415

    if args.gain not in tune.GAINS:
        raise ScenarioError(f"--gain: must be one of {', '.join(tune.GAINS)}, got {args.gain!r}")
    if not args.margin >= 1.0:
        raise ScenarioError(f"--margin: must be >= 1, got {args.margin}")
    if not 0.0 <= args.max_saturation <= 1.0:
        raise ScenarioError(f"--max-saturation: must be in [0, 1], got {args.max_saturation}")
    variants = [v.strip() for v in args.variants.split(",") if v.strip()]
    if not variants:
        raise ScenarioError("--variants: no values given")
    where = _where(args)
    _out_dir(args.out, Path("out"))
    scenario = load(args.scenario, args.set)
    name, text = load_text(args.scenario, args.set)
    out = _out_dir(args.out, Path("out") / f"tune_{scenario.name}")
    settings = tune.TuneSettings(gain=args.gain, variants=tuple(variants), margin=args.margin,
                                 max_saturation=args.max_saturation)
    say = (lambda message: None) if args.quiet else (lambda message: print(message, file=sys.stderr))
    result = _dask_errors(lambda: tune.run_tune(text, name, settings, progress=_runs("tune", args.quiet),
                                                say=say, **where))
    tune.write_tune(result, out)
    print(tune.summary_line(result))
    if result["gains"] is None:
        print(f"ptint: no tuned.yaml written; wrote {out}/tune.json, tune.png", file=sys.stderr)
        return 1
    print(f"wrote {out}/tuned.yaml (run it: ptint run {out}/tuned.yaml), tune.json, tune.png")
    return 0


def cmd_study(args) -> int:
    from ptint_drake.studies import camera  # noqa: PLC0415

    if args.seeds < 1:
        raise ScenarioError(f"--seeds: must be >= 1, got {args.seeds}")
    if args.workers < 1:
        raise ScenarioError(f"--workers: must be >= 1, got {args.workers}")
    report = None if args.quiet else (
        lambda i, n, *_: print(f"study camera: {i}/{n} runs", file=sys.stderr)
        if i % 10 == 0 or i == n else None)
    if args.filter_floor:
        return _filter_floor(args, camera, report)
    for flag, value in (("--scenario", args.scenario), ("--process-noise", args.process_noise),
                        ("--set", args.set)):
        if value is not None:
            raise ScenarioError(f"{flag}: only with --filter-floor")
    out = _out_dir(args.out, Path("out") / f"study_{args.study}")
    result = camera.run_study(seeds=args.seeds, workers=args.workers, out=out, progress=report)
    runs = sum(row["summary"]["runs"] for row in result["table"])
    errors = sum(row["summary"]["errors"] for row in result["table"])
    print(f"{runs} runs ({errors} could not run) in {result['wall_time_s']:.0f} s with "
          f"{args.workers} workers; wrote {out}/camera_study.md, camera_study.json, estimate.png")
    return 0


def _filter_floor(args, camera, report) -> int:
    """``ptint study camera --filter-floor``: the camera + Kalman filter alone, per q and seed."""
    noises = _floats(args.process_noise, "--process-noise") if args.process_noise is not None \
        else list(camera.FLOOR_PROCESS_NOISES)
    for q in noises:
        if not (q > 0.0 and q != float("inf")):  # NaN fails the first test
            raise ScenarioError(f"--process-noise: every value must be > 0 and finite, got {q:g}")
    _out_dir(args.out, Path("out"))
    scenario = load(args.scenario or camera.FLOOR_SCENARIO, args.set)
    name, text = load_text(args.scenario or camera.FLOOR_SCENARIO, args.set)
    out = _out_dir(args.out, Path("out") / f"filter_floor_{scenario.name}")
    result = camera.filter_floor(text, name, noises, args.seeds, workers=args.workers, progress=report)
    camera.write_filter_floor(result, out)
    print(f"{camera.floor_summary_line(result)}; wrote {out}/filter_floor.md, filter_floor.json")
    return 0


def cmd_bench(args) -> int:
    from ptint_drake.studies.benchmark import main as bench_main  # noqa: PLC0415

    return bench_main(args.rest)


SET_HELP = ("override a scenario field (repeatable); KEY is a path with dots and list "
            "indices, VALUE is YAML, e.g. controller.K=40 or 'interceptions[0].tf=1.2' "
            "(README: Scenario files)")
RESULTS = "Criteria of an interception: README, Results (|e(tf)| <= 1 mm, hold <= 3 mm)."


def _study_arguments(parser, default_out: str, workers_default: str = "CPU count") -> None:
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help=f"worker processes (default: {workers_default})")
    where.add_argument("--dask", metavar="ADDRESS", help="run on this Dask scheduler (tcp://host:8786)")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    parser.add_argument("--out", help=f"output folder (default {default_out})")
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ptint", description=__doc__.split("\n")[0],
        epilog="Paper: Flores-Campos et al., Robotics 2024, 13(10), 145. "
               "README: Command line, Scenario files.")
    sub = parser.add_subparsers(dest="command", required=True)
    _add_run_parsers(sub)
    _add_study_parsers(sub)
    return parser


def _add_run_parsers(sub) -> None:
    """list, run, diagram, paper."""
    sub.add_parser("list", help="names of the bundled scenarios",
                   description="The bundled scenarios (paper section 3, Table 1; README: "
                               "Scenario files).").set_defaults(func=cmd_list)

    run = sub.add_parser(
        "run", help="run one scenario and write its outputs",
        description="Simulate one scenario: the TBG (paper eqs. 6-10), the sliding surface "
                    "(eqs. 11, 16, 17) and the controller (eq. 18) on the robot; writes "
                    "metrics.json, series.npz, figures and replay.html. Exit 0 when every segment "
                    "meets the scenario's criteria, 1 when one missed them (late, early, hold) or "
                    "the run diverged, 2 on bad input (README: Command line, Results).", epilog=RESULTS)
    run.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    run.add_argument("--out", help="output folder (default out/NAME)")
    run.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    run.add_argument("--no-replay", action="store_true", help="skip replay.html")
    run.add_argument("--no-figures", action="store_true", help="skip the figures")
    run.add_argument("--quiet", action="store_true", help="no progress on stderr")
    run.set_defaults(func=cmd_run)

    diagram = sub.add_parser(
        "diagram", help="write the built diagram as .dot and .svg",
        description="The scenario's Drake diagram (paper Fig. 1: TBG, targets, kinematics, "
                    "surface, controller, plant) as Graphviz NAME.dot and NAME.svg.")
    diagram.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    diagram.add_argument("--out", help="output folder (default out/NAME)")
    diagram.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    diagram.add_argument("--quiet", action="store_true", help="accepted like the other commands")
    diagram.set_defaults(func=cmd_diagram)

    paper = sub.add_parser(
        "paper", help="reproduce the paper: every scenario, figures, comparisons, index.html",
        description="Run the five curve scenarios (paper Figs. 6-15) and the assembly task "
                    "(Figs. 16-19), draw the TBG and α families (Figs. 2-4), compare the "
                    "controllers on curve_b075_tf15 and assembly, and write DIR/index.html "
                    "(README: Quick start).", epilog=RESULTS)
    paper.add_argument("--out", default="out/paper", help="output folder (default out/paper)")
    paper.add_argument("--quiet", action="store_true", help="no progress on stderr")
    paper.set_defaults(func=cmd_paper)


def _add_study_parsers(sub) -> None:
    """sweep, robust, compare, tune, study, bench: many runs, on worker processes or Dask."""
    sw = sub.add_parser(
        "sweep", help="β × tf grid in parallel worker processes",
        description="Run the scenario on a grid of TBG shapes β and prescribed times tf "
                    "(paper eq. 6), every segment getting the grid's values; writes sweep.csv "
                    "and heat maps (README: Sweeps).", epilog=RESULTS)
    sw.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    sw.add_argument("--beta", default="0.25,0.5,0.75",
                    help="comma-separated β values in (0, 1) (paper eq. 6; default %(default)s)")
    sw.add_argument("--tf", default="1.2,1.5,1.9",
                    help="comma-separated prescribed times tf in s (default %(default)s)")
    _study_arguments(sw, "out/sweep_NAME")
    sw.set_defaults(func=cmd_sweep)

    rb = sub.add_parser(
        "robust", help="Monte Carlo study over unknown dynamics and disturbances",
        description="Monte Carlo over what the controller does not know: masses, friction, "
                    "payload, the disturbance d of paper eq. 1, measurement noise (README: "
                    "Robustness and safety); writes robust.json, samples.json, worst.yaml and "
                    "a histogram.", epilog=RESULTS)
    rb.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    rb.add_argument("--samples", type=int, default=100, help="number of samples (default 100)")
    rb.add_argument("--seed", type=int, default=0, help="sample i uses seed + i")
    rb.add_argument("--range", action="append", metavar="NAME=LOW,HIGH",
                    help="override a parameter range (mass, friction, coulomb, payload, "
                         "disturbance, noise, latency)")
    _study_arguments(rb, "out/robust_NAME", workers_default="1")
    rb.set_defaults(func=cmd_robust)

    _add_design_parsers(sub)
    st = sub.add_parser(
        "study", help="studies: camera (|e(tf)| against noise × latency × estimator)",
        description="camera: |e(tf)| on conveyor_pair_camera over noise × latency × estimator "
                    "(camera_study.md/.json, estimate.png). camera --filter-floor: the camera and "
                    "Kalman filter alone (no arm) on a camera scenario, per process noise: the "
                    "largest |estimate − true object| over each hold window, the error a controller "
                    "that follows the estimate inherits (filter_floor.md/.json).")
    st.add_argument("study", choices=["camera"])
    st.add_argument("--seeds", type=int, default=10, help="seeds per grid point (default 10)")
    st.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    st.add_argument("--out", help="output folder (default out/study_camera, with --filter-floor "
                                  "out/filter_floor_NAME)")
    st.add_argument("--quiet", action="store_true")
    st.add_argument("--filter-floor", action="store_true",
                    help="measure the camera + Kalman filter alone (no arm) per process noise")
    st.add_argument("--scenario", help="with --filter-floor: a camera scenario (bundled name or YAML "
                                       "file with a kalman_cv/kalman_ca estimator; default curve_camera)")
    st.add_argument("--process-noise", metavar="Q,..",
                    help="with --filter-floor: comma-separated process noises q > 0 "
                         "(default 0.003,0.01,0.03,0.1,0.3)")
    st.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="with --filter-floor: " + SET_HELP)
    st.set_defaults(func=cmd_study)
    # `ptint bench ARGS` hands ARGS (--help included) to the benchmark's own parser (see main)
    bench = sub.add_parser("bench", help="speed/accuracy benchmark as JSON (ptint bench --help)",
                           add_help=False)
    bench.add_argument("rest", nargs=argparse.REMAINDER)
    bench.set_defaults(func=cmd_bench)


def _add_design_parsers(sub) -> None:
    """compare (controllers × plant variants) and tune (gains for an arm)."""
    cmp_ = sub.add_parser(
        "compare", help="controllers side by side on plant variants (README: Controllers compared)",
        description="Every controller × plant variant on the same scenario, in parallel; writes "
                    "compare.json, compare.csv, compare.md and compare.png. Exit 0 when every run "
                    "completed (a miss is a result), 2 on bad input.")
    cmp_.add_argument("scenario", help="a bundled scenario name or a YAML file")
    cmp_.add_argument("--controllers", default="ptsmc,pd,smc,ct_quintic",
                      help="comma-separated: ptsmc (the paper's), pd, smc, ct_quintic")
    cmp_.add_argument("--variants", default="nominal,mass_x0.7,mass_x1.5",
                      help="comma-separated plant variants: nominal, mass_xF, payload_Mkg")
    _study_arguments(cmp_, "out/compare_NAME")
    cmp_.set_defaults(func=cmd_compare)

    tn = sub.add_parser(
        "tune",
        help="the smallest gain that meets the prescribed time on every variant (README: Your own arm)",
        description="1-D search of one gain (K or Lambda: the smallest that works; phi: the largest) so "
                    "that every segment meets the criteria divided by --margin on every plant variant "
                    "and the actuators saturate at most --max-saturation of the time. Writes tuned.yaml "
                    "(only when a value works), tune.json and tune.png. Exit 0 when found, 1 when no "
                    "value in the range works, 2 on bad input.")
    tn.add_argument("scenario", help="a bundled scenario name or a YAML file")
    tn.add_argument("--gain", default="K", help="K (default), Lambda or phi")
    tn.add_argument("--variants", default="nominal,mass_x0.7,mass_x1.5",
                    help="comma-separated plant variants: nominal, mass_xF, payload_Mkg")
    tn.add_argument("--margin", type=float, default=2.0, help="e(tf) ≤ 1 mm / M, hold ≤ 3 mm / M (default 2)")
    tn.add_argument("--max-saturation", type=float, default=0.05,
                    help="largest fraction of the time an actuator may saturate (default 0.05)")
    _study_arguments(tn, "out/tune_NAME")
    tn.set_defaults(func=cmd_tune)


def _run(argv) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["bench"]:  # everything after it, --help included, is the benchmark's
        args = argparse.Namespace(func=cmd_bench, rest=argv[1:])
    else:
        args = make_parser().parse_args(argv)
    try:
        return args.func(args)
    except ScenarioError as exc:
        print(f"ptint: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\nptint: interrupted; no partial output was kept", file=sys.stderr)
        return 130
    except BrokenPipeError:
        raise
    except OSError as exc:  # e.g. an --out folder that cannot be written
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"ptint: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 1
    except ImportError as exc:  # Ctrl-C while a compiled module (pydrake) initializes
        cause = exc
        while cause is not None and not isinstance(cause, KeyboardInterrupt):
            cause = cause.__cause__ or cause.__context__
        if cause is None:
            raise
        print("\nptint: interrupted; no partial output was kept", file=sys.stderr)
        return 130
    except RuntimeError as exc:  # Drake's simulation errors
        print(f"ptint: error: simulation failed: {' '.join(str(exc).split())[:400]}", file=sys.stderr)
        return 1


def main(argv=None) -> int:
    try:
        code = _run(argv)
        sys.stdout.flush()  # a closed pipe shows up here, not at interpreter exit
        return code
    except BrokenPipeError:
        # The reader went away (`ptint list | head -1`): stop quietly.  Python's
        # documented recipe: point stdout at devnull so the flush at exit cannot fail again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 1


if __name__ == "__main__":
    sys.exit(main())
