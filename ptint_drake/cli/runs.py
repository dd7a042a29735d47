"""The commands that run one scenario or the paper: ``ptint list``, ``run``, ``diagram``, ``paper``,
and their progress bar on stderr."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ptint_drake.cli.options import out_folder, scenario_and_out
from ptint_drake.simulation.scenario import LoadedScenario, bundled_scenarios, scenario_summary, scenario_text
from ptint_drake.worlds.registry import world_of


def progress(label: str):
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


def cmd_list(args: argparse.Namespace) -> int:
    """Each bundled scenario's name and its one-line summary (``scenario_summary``)."""
    names = bundled_scenarios()
    width = max(len(name) for name in names)
    for name in names:
        print(f"{name:<{width}}  {scenario_summary(scenario_text(name)[1])}")
    return 0


def _mm(value) -> str:
    return "n/a" if value is None else f"{value * 1e3:.4g} mm"


def _mm_deg(seg: dict, distance: str, angle: str) -> str:
    """A distance, with the orientation angle beside it when the task has one."""
    value = seg.get(angle)
    return _mm(seg[distance]) + ("" if value is None else f" / {value:.3g}°")


def _segment_line(name: str, i: int, seg: dict, criteria) -> str:
    from ptint_drake.verdict.metrics import segment_reasons  # noqa: PLC0415

    reasons = segment_reasons(seg, criteria)
    return (f"{name} segment {i}: e0 = {_mm_deg(seg, 'e0_norm', 'e_rot0_deg')}, "
            f"e(tf/2) = {_mm_deg(seg, 'e_half_norm', 'e_rot_half_deg')}, "
            f"e(tf) = {_mm_deg(seg, 'e_tf_norm', 'e_rot_tf_deg')}, "
            f"hold max = {_mm_deg(seg, 'e_hold_max_norm', 'e_rot_hold_max_deg')}: "
            + (f"MISSED ({', '.join(reasons)})" if reasons else "ok"))


def _sim_line(metrics: dict, out) -> str:
    """The run's cost line: what every world's ``sim`` block has (the realtime factor, the steps),
    and the derivative evaluations and saturation where the world reports them."""
    sim = metrics["sim"]
    parts = [f"realtime factor {sim['realtime_factor']:.2f} end to end", f"{sim['steps']} steps"]
    if "derivative_evaluations" in sim:
        parts.append(f"{sim['derivative_evaluations']} derivative evaluations")
    if metrics.get("saturated_fraction") is not None:
        parts[-1] += f", saturated {100 * metrics['saturated_fraction']:.1f} % of the time"
    return ", ".join(parts) + f"; wrote {out}/"


def opening_line(name: str, world: str, duration: float, controller: str, out: Path) -> str:
    """The first line of ``ptint run``: what is run, for how long, by which controller, and
    where its outputs go."""
    return (f"running {name}: the {world} world, {duration:g} s simulated, controller {controller} "
            f"(its settings: --verbose); outputs in {out}/")


def cmd_run(args: argparse.Namespace) -> int:
    """One scenario: its outputs, a line per segment; exit 1 when a segment missed or the run failed."""
    from ptint_drake.report.run_outputs import run_and_write  # noqa: PLC0415

    loaded, out = scenario_and_out(args)
    scenario = loaded.scenario
    print(opening_line(scenario.name, world_of(scenario).name, scenario.duration,
                       scenario.controller.type, out), flush=True)
    warn = lambda message: print(f"ptint: warning: {message}", file=sys.stderr)  # noqa: E731
    metrics = run_and_write(scenario, out, replay=not args.no_replay,
                            figures=not args.no_figures, svg=args.svg,
                            progress=None if args.quiet else progress(scenario.name), warn=warn)
    for note in metrics["controller"]["notes"]:
        if args.verbose or ": warning: " in note:  # the settings on request, a warning always
            print(note)
    own = world_of(scenario).report(scenario, metrics, out)  # a world's own lines, if it has them
    if own is not None:
        return own
    for i, seg in enumerate(metrics["segments"]):
        print(_segment_line(scenario.name, i, seg, scenario.criteria))
    print(_sim_line(metrics, out))
    for message in metrics["warnings"][metrics["warnings_before_run"]:]:
        warn(message)
    if metrics["status"] == "failed":
        print(f"ptint: error: run failed: {metrics['failure']['message']} "
              f"(outputs up to then are in {out}/, metrics.json says status: failed)", file=sys.stderr)
        return 1
    if metrics["status"] == "missed":
        print(missed_line(scenario, metrics, args.scenario))
        return 1
    print(f"{scenario.name}: ok (every segment meets the criteria)")
    return 0


def missed_line(scenario, metrics: dict, name: str) -> str:
    """A missed run's line: its reasons, and ``ptint tune`` suggested only where the scenario's
    world can be tuned (``World.tune_refusal``: a catch's or a pick's miss is not the gains')."""
    tunable = world_of(scenario).tune_refusal(name) is None
    hint = f"; the gains may not fit this arm or tf: try `ptint tune {name}`" if tunable else ""
    return f"{scenario.name}: MISSED ({'; '.join(metrics['reasons'])}){hint}"


def cmd_diagram(args: argparse.Namespace) -> int:
    """The scenario's diagram as Graphviz .dot and .svg."""
    from ptint_drake.report.run_outputs import write_diagram  # noqa: PLC0415

    scenario = LoadedScenario.load(args.scenario, args.set).scenario
    out = out_folder(args.out, Path("out") / scenario.name)
    paths = write_diagram(scenario, out)
    print("wrote " + ", ".join(str(p) for p in paths))
    return 0


def cmd_paper(args: argparse.Namespace) -> int:
    """Every paper scenario, the TBG figures and index.html; the last line counts the scenarios
    reproduced (``paper_report.summary_line``)."""
    from ptint_drake.report.paper_report import summary_line, write_paper  # noqa: PLC0415

    def notify(message: str) -> None:
        print(f"paper: {message}", file=sys.stderr, flush=True)

    index, metrics = write_paper(out_folder(args.out, Path("out/paper")),
                                 progress_factory=None if args.quiet else progress, svg=args.svg,
                                 notify=None if args.quiet else notify)
    print(f"wrote {index}")
    print(summary_line(metrics, index))
    return 0
