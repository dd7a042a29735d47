"""The ``ptint`` command line (SPEC section 5.1).

    ptint list                              bundled scenarios
    ptint run NAME_OR_FILE [--out DIR]      one scenario: metrics.json, series.npz, figures, replay.html
    ptint paper [--out DIR]                 every paper scenario + TBG figures + index.html
    ptint diagram NAME_OR_FILE [--out DIR]  the built diagram as Graphviz .dot and .svg
    ptint sweep NAME_OR_FILE --beta B,.. --tf T,.. [--workers N] [--out DIR]   grid → sweep.csv
    ptint robust NAME_OR_FILE --samples N [--seed S] [--workers W] [--out DIR]   Monte Carlo
    ptint bench [SCENARIO ...]              speed and accuracy benchmark, JSON on stdout

``--set key=value`` (repeatable) overrides a scenario field, e.g.
``--set controller.switching=sign --set simulator.accuracy=1e-6``; values are
YAML.  Bad input ends with one line ``ptint: error: FIELD: ...`` and exit 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ptint_drake.scenario import ScenarioError, bundled_scenarios, scenario_text


def _parse_overrides(pairs) -> str:
    """``a.b=v`` pairs as one nested YAML mapping (text)."""
    import yaml  # noqa: PLC0415  (PyYAML ships with drake's dependencies)

    tree: dict = {}
    for pair in pairs or []:
        if "=" not in pair:
            raise ScenarioError(f"--set: expected key=value, got {pair!r}")
        key, value = pair.split("=", 1)
        node = tree
        parts = key.strip().split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
        try:
            node[parts[-1]] = yaml.safe_load(value)
        except yaml.YAMLError:
            raise ScenarioError(f"--set {key}: value {value!r} is not valid YAML") from None
    return yaml.safe_dump(tree) if tree else ""


def load(name_or_file: str, overrides=None):
    from ptint_drake.scenario import parse_scenario, parse_with_overrides  # noqa: PLC0415

    name, text = scenario_text(name_or_file)
    extra = _parse_overrides(overrides)
    if extra:
        return parse_with_overrides(text, extra, name)
    return parse_scenario(text, name)


def _progress(label: str):
    """A progress line on stderr: redrawn in place on a terminal, one line at the end otherwise."""
    tty = sys.stderr.isatty()

    def report(t, duration):
        if not tty and t < duration:
            return
        width = 30
        done = int(width * min(t / duration, 1.0))
        end = "\n" if t >= duration else ""
        sys.stderr.write(f"\r{label:<18} [{'#' * done}{'.' * (width - done)}] "
                         f"{t:5.2f}/{duration:.2f} s simulated{end}")
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
    from ptint_drake.report import run_and_write  # noqa: PLC0415

    scenario = load(args.scenario, args.set)
    out = Path(args.out) if args.out else Path("out") / scenario.name
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
    from ptint_drake.report import write_diagram  # noqa: PLC0415

    scenario = load(args.scenario, args.set)
    out = Path(args.out) if args.out else Path("out") / scenario.name
    paths = write_diagram(scenario, out)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_paper(args) -> int:
    from ptint_drake.report import write_paper  # noqa: PLC0415

    index = write_paper(Path(args.out), progress_factory=None if args.quiet else _progress)
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


def cmd_sweep(args) -> int:
    from ptint_drake.studies import sweep  # noqa: PLC0415
    from ptint_drake.outputs import staged_output  # noqa: PLC0415

    betas, tfs = _floats(args.beta, "--beta"), _floats(args.tf, "--tf")
    for b in betas:
        if not 0.0 < b < 1.0:
            raise ScenarioError(f"--beta: every value must be in (0, 1), got {b}")
    for tf in tfs:
        if not tf > 0.0:
            raise ScenarioError(f"--tf: every value must be > 0, got {tf}")
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers: must be >= 1, got {args.workers}")
    scenario = load(args.scenario)  # validates the base scenario before any worker starts
    name, text = scenario_text(args.scenario)
    out = Path(args.out) if args.out else Path("out") / f"sweep_{scenario.name}"
    report = None if args.quiet else (lambda i, n: print(f"sweep: {i}/{n} runs done", file=sys.stderr))
    rows = sweep.run_sweep(text, name, betas, tfs, workers=args.workers, progress=report)
    with staged_output(out) as stage:
        sweep.heatmaps(rows, betas, tfs, stage, f"{scenario.name}: β × tf sweep")
        sweep.write_csv(rows, stage / "sweep.csv")
    ok = sum(1 for r in rows if r.get("ok"))
    print(f"{len(rows)} runs, {ok} meet the prescribed-time property; wrote {out}/sweep.csv")
    return 0


def cmd_robust(args) -> int:
    from ptint_drake.studies import robust  # noqa: PLC0415

    if args.samples < 1:
        raise ScenarioError(f"--samples: must be >= 1, got {args.samples}")
    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers: must be >= 1, got {args.workers}")
    ranges = dict(robust.RANGES)
    for pair in args.range or []:
        key, _, value = pair.partition("=")
        if key not in ranges:
            raise ScenarioError(f"--range: unknown parameter {key!r} (one of {', '.join(ranges)})")
        lo_hi = _floats(value, f"--range {key}")
        if len(lo_hi) != 2 or lo_hi[0] > lo_hi[1] or lo_hi[0] < 0:
            raise ScenarioError(f"--range {key}: expected LOW,HIGH with 0 <= LOW <= HIGH, got {value!r}")
        ranges[key] = tuple(lo_hi)
    scenario = load(args.scenario)
    name, text = scenario_text(args.scenario)
    out = Path(args.out) if args.out else Path("out") / f"robust_{scenario.name}"
    report = None if args.quiet else (
        lambda i, n: print(f"robust: {i}/{n} samples", file=sys.stderr) if i % 10 == 0 or i == n else None)
    result = robust.run_robust(text, name, args.samples, args.seed, args.workers, ranges=ranges,
                               progress=report)
    robust.write_robust(result, out)
    p = result["e_tf_percentiles"]
    print(f"{result['samples']} samples, success rate {100 * result['success_rate']:.1f} %, "
          f"e(tf) p50 {p.get('p50', float('nan')) * 1e3:.4f} mm, max {p.get('max', float('nan')) * 1e3:.4f} mm; "
          f"worst seed {result['worst']['seed']}; wrote {out}/robust.json")
    return 0


def cmd_study(args) -> int:
    from ptint_drake.studies import camera  # noqa: PLC0415

    if args.seeds < 1:
        raise ScenarioError(f"--seeds: must be >= 1, got {args.seeds}")
    if args.workers < 1:
        raise ScenarioError(f"--workers: must be >= 1, got {args.workers}")
    out = Path(args.out) if args.out else Path("out") / f"study_{args.study}"
    report = None if args.quiet else (
        lambda i, n: print(f"study camera: {i}/{n} runs", file=sys.stderr) if i % 10 == 0 or i == n else None)
    result = camera.run_study(seeds=args.seeds, workers=args.workers, out=out, progress=report)
    runs = sum(row["summary"]["runs"] for row in result["table"])
    errors = sum(row["summary"]["errors"] for row in result["table"])
    print(f"{runs} runs ({errors} could not run) in {result['wall_time_s']:.0f} s with "
          f"{args.workers} workers; wrote {out}/camera_study.md, camera_study.json, estimate.png")
    return 0


def cmd_bench(args) -> int:
    from ptint_drake.studies.benchmark import main as bench_main  # noqa: PLC0415

    return bench_main(args.rest)


def make_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="ptint", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="names of the bundled scenarios").set_defaults(func=cmd_list)

    run = sub.add_parser("run", help="run one scenario and write its outputs")
    run.add_argument("scenario", help="a bundled scenario name or a YAML file")
    run.add_argument("--out", help="output folder (default out/NAME)")
    run.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario field")
    run.add_argument("--no-replay", action="store_true", help="skip replay.html")
    run.add_argument("--no-figures", action="store_true", help="skip the figures")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.set_defaults(func=cmd_run)

    diagram = sub.add_parser("diagram", help="write the built diagram as .dot and .svg")
    diagram.add_argument("scenario")
    diagram.add_argument("--out", help="output folder (default out/NAME)")
    diagram.add_argument("--set", action="append", metavar="KEY=VALUE")
    diagram.set_defaults(func=cmd_diagram)

    sw = sub.add_parser("sweep", help="β × tf grid in parallel worker processes")
    sw.add_argument("scenario")
    sw.add_argument("--beta", default="0.25,0.5,0.75", help="comma-separated β values")
    sw.add_argument("--tf", default="1.2,1.5,1.9", help="comma-separated tf values (s)")
    sw.add_argument("--workers", type=int, help="worker processes (default: CPU count)")
    sw.add_argument("--out", help="output folder (default out/sweep_NAME)")
    sw.add_argument("--quiet", action="store_true")
    sw.set_defaults(func=cmd_sweep)

    rb = sub.add_parser("robust", help="Monte Carlo study over unknown dynamics and disturbances")
    rb.add_argument("scenario")
    rb.add_argument("--samples", type=int, default=100)
    rb.add_argument("--seed", type=int, default=0, help="sample i uses seed + i")
    rb.add_argument("--workers", type=int, help="worker processes (default 1)")
    rb.add_argument("--range", action="append", metavar="NAME=LOW,HIGH",
                    help="override a parameter range (mass, friction, coulomb, payload, "
                         "disturbance, noise, latency)")
    rb.add_argument("--out", help="output folder (default out/robust_NAME)")
    rb.add_argument("--quiet", action="store_true")
    rb.set_defaults(func=cmd_robust)

    st = sub.add_parser("study", help="studies: camera (|e(tf)| against noise × latency × estimator)")
    st.add_argument("study", choices=["camera"])
    st.add_argument("--seeds", type=int, default=10, help="seeds per grid point (default 10)")
    st.add_argument("--workers", type=int, default=2, help="worker processes (default 2)")
    st.add_argument("--out", help="output folder (default out/study_camera)")
    st.add_argument("--quiet", action="store_true")
    st.set_defaults(func=cmd_study)

    bench = sub.add_parser("bench", help="speed/accuracy benchmark as JSON (see --help there)",
                           add_help=False)
    bench.add_argument("rest", nargs=argparse.REMAINDER)
    bench.set_defaults(func=cmd_bench)

    paper = sub.add_parser("paper", help="reproduce the paper: every scenario, figures, index.html")
    paper.add_argument("--out", default="out/paper", help="output folder (default out/paper)")
    paper.add_argument("--quiet", action="store_true")
    paper.set_defaults(func=cmd_paper)
    return parser


def main(argv=None) -> int:
    args = make_parser().parse_args(argv)
    try:
        return args.func(args)
    except ScenarioError as exc:
        print(f"ptint: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("\nptint: interrupted; no partial output was kept", file=sys.stderr)
        return 130
    except RuntimeError as exc:  # Drake's simulation errors
        print(f"ptint: error: simulation failed: {' '.join(str(exc).split())[:400]}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
