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
    ptint hardware NAME_OR_FILE [--lockstep]  the simulated world as hardware over LCM
    ptint drive NAME_OR_FILE                the controller alone over LCM (docs/hardware.md)
    ptint --version                         this package's version and Drake's

``--set key=value`` (repeatable) overrides any scenario field, list items
included, e.g. ``--set controller.switching=sign --set 'interceptions[0].tf=1.2'``;
values are YAML.  Bad input ends with one line ``ptint: error: FIELD: ...`` and exit 2.
"""

from __future__ import annotations

import argparse
import gc
import importlib.metadata
import os
import platform
import sys

from ptint_drake.cli import options as opt
from ptint_drake.cli.hardware import add_hardware_parsers
from ptint_drake.cli.runs import cmd_diagram, cmd_list, cmd_paper, cmd_run
from ptint_drake.cli.studies import cmd_bench, cmd_compare, cmd_robust, cmd_study, cmd_sweep, cmd_tune
from ptint_drake.controllers import CONTROLLERS, describe
from ptint_drake.simulation.scenario import ScenarioError

SET_HELP = ("override a scenario field (repeatable); KEY is a path with dots and list "
            "indices, VALUE is YAML, e.g. controller.K=40 or 'interceptions[0].tf=1.2' "
            "(docs/scenarios.md)")
RESULTS = "Criteria of an interception: docs/results.md (|e(tf)| <= 1 mm, hold <= 3 mm)."


def _study_arguments(parser, default_out: str, workers_default: str = "CPU count") -> None:
    """The options every study shares: --workers | --dask, --set, --out, --quiet."""
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--workers", type=opt.count("--workers"),
                       help=f"worker processes (default: {workers_default})")
    where.add_argument("--dask", metavar="ADDRESS", help="run on this Dask scheduler (tcp://host:8786)")
    parser.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    parser.add_argument("--out", help=f"output folder (default {default_out})")
    parser.add_argument("--quiet", action="store_true", help="no progress on stderr")


def version_text() -> str:
    """``ptint --version``: this package's version, Drake's and Python's, read from the installed
    distributions' metadata (no pydrake import, so it answers at once)."""
    def installed(name: str) -> str:
        try:
            return importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            return "not installed"

    return (f"ptint (ptint_drake) {installed('ptint_drake')}, Drake {installed('drake')}, "
            f"Python {platform.python_version()}")


def make_parser() -> argparse.ArgumentParser:
    """``ptint``'s parser: each subcommand with its options, each option value checked by its
    type (``cli.options``), ``func`` the command (``cli.runs``, ``cli.studies``)."""
    parser = argparse.ArgumentParser(
        prog="ptint", description=__doc__.split("\n")[0],
        epilog="Paper: Flores-Campos et al., Robotics 2024, 13(10), 145. "
               "Documentation: docs/cli.md, docs/scenarios.md.")
    parser.add_argument("--version", action="version", version=version_text(),
                        help="print the package's, Drake's and Python's versions and exit")
    sub = parser.add_subparsers(dest="command", required=True)
    _add_run_parsers(sub)
    _add_grid_parsers(sub)
    _add_design_parsers(sub)
    _add_camera_parsers(sub)
    _add_bench_parser(sub)
    add_hardware_parsers(sub)
    return parser


def _add_run_parsers(sub) -> None:
    """list, run, diagram, paper."""
    sub.add_parser("list", help="names of the bundled scenarios",
                   description="The bundled scenarios (paper section 3, Table 1; "
                               "docs/scenarios.md).").set_defaults(func=cmd_list)

    run = sub.add_parser(
        "run", help="run one scenario and write its outputs",
        description="Simulate one scenario: the TBG (paper eqs. 6-10), the sliding surface "
                    "(eqs. 11, 16, 17) and the controller (eq. 18) on the robot; writes "
                    "metrics.json, series.npz, figures and replay.html. Exit 0 when every segment "
                    "meets the scenario's criteria, 1 when one missed them (late, early, hold) or "
                    "the run diverged, 2 on bad input (docs/cli.md, docs/results.md).", epilog=RESULTS)
    run.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    run.add_argument("--out", help="output folder (default out/NAME)")
    run.add_argument("--set", action="append", metavar="KEY=VALUE", help=SET_HELP)
    run.add_argument("--no-replay", action="store_true", help="skip replay.html")
    run.add_argument("--no-figures", action="store_true", help="skip the figures")
    run.add_argument("--svg", action="store_true", help="the figures as SVG too (PNG always)")
    run.add_argument("--quiet", action="store_true", help="no progress on stderr")
    run.add_argument("--verbose", action="store_true",
                     help="print the controller's settings (gains, switching law, sampling)")
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
                    "(docs/quickstart.md).", epilog=RESULTS)
    paper.add_argument("--out", default="out/paper", help="output folder (default out/paper)")
    paper.add_argument("--quiet", action="store_true", help="no progress on stderr")
    paper.add_argument("--svg", action="store_true", help="the run figures as SVG too (PNG always)")
    paper.set_defaults(func=cmd_paper)


def _add_grid_parsers(sub) -> None:
    """sweep and robust: many runs of one scenario, on worker processes or Dask."""
    sw = sub.add_parser(
        "sweep", help="β × tf grid in parallel worker processes",
        description="Run the scenario on a grid of TBG shapes β and prescribed times tf "
                    "(paper eq. 6), every segment getting the grid's values; writes sweep.csv "
                    "and heat maps (docs/sweeps.md).", epilog=RESULTS)
    sw.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    sw.add_argument("--beta", type=opt.betas, action=opt.Items, default="0.25,0.5,0.75",
                    help="β values in (0, 1), comma-separated or repeated (paper eq. 6; "
                         "default %(default)s)")
    sw.add_argument("--tf", type=opt.final_times, action=opt.Items, default="1.2,1.5,1.9",
                    help="prescribed times tf in s, comma-separated or repeated (default %(default)s)")
    _study_arguments(sw, "out/sweep_NAME")
    sw.set_defaults(func=cmd_sweep)

    rb = sub.add_parser(
        "robust", help="Monte Carlo study over unknown dynamics and disturbances",
        description="Monte Carlo over what the controller does not know: masses, friction, "
                    "payload, the disturbance d of paper eq. 1, camera noise "
                    "(docs/robustness.md); writes robust.json, samples.json, worst.yaml and "
                    "a histogram.", epilog=RESULTS)
    rb.add_argument("scenario", help="a bundled scenario name (ptint list) or a YAML file")
    rb.add_argument("--samples", type=opt.count("--samples"), default=100,
                    help="number of samples (default 100)")
    rb.add_argument("--seed", type=int, default=0, help="sample i uses seed + i")
    rb.add_argument("--range", action="append", type=opt.robust_range, metavar="NAME=LOW,HIGH",
                    help="override a parameter range (mass, friction, coulomb, payload, "
                         "disturbance, noise, latency; pick scenarios: part_mass, part_friction, "
                         "belt_speed, close_jitter, part_lateral; rgbd picks: camera_xyz_error, "
                         "camera_rpy_error, depth_noise_scale, placed_lateral)")
    rb.add_argument("--ranges", type=opt.ranges_preset, default="harsh", metavar="PRESET",
                    help="the preset of ranges: harsh (default; pick ranges that reach failures), "
                         "mild (the study before them, seed for seed) or calibration (mild with an "
                         "rgbd camera's calibration error at +-2 mm, +-0.5 deg)")
    _study_arguments(rb, "out/robust_NAME", workers_default="1")
    rb.set_defaults(func=cmd_robust)


def _add_design_parsers(sub) -> None:
    """compare (controllers × plant variants) and tune (gains for an arm)."""
    cmp_ = sub.add_parser(
        "compare", help="controllers side by side on plant variants (docs/controllers.md)",
        description="Every controller × plant variant on the same scenario, in parallel; writes "
                    "compare.json, compare.csv, compare.md and compare.png. Exit 0 when every run "
                    "completed (a miss is a result), 2 on bad input.")
    cmp_.add_argument("scenario", help="a bundled scenario name or a YAML file")
    cmp_.add_argument("--controllers", type=opt.controller_list, action=opt.Items,
                      default=",".join(CONTROLLERS),
                      help="comma-separated or repeated, default every registered one: "
                           + "; ".join(describe().splitlines()))
    cmp_.add_argument("--variants", type=opt.variant_list, action=opt.Items,
                      default="nominal,mass_x0.7,mass_x1.5",
                      help="plant variants, comma-separated or repeated: nominal, mass_xF, payload_Mkg")
    _study_arguments(cmp_, "out/compare_NAME")
    cmp_.set_defaults(func=cmd_compare)

    tn = sub.add_parser(
        "tune",
        help="the smallest gain that meets the prescribed time on every variant (docs/own_arm.md)",
        description="1-D search of one gain (K, Lambda or rot_scale: the smallest that works; phi: the "
                    "largest) so that every segment meets the criteria divided by --margin on every plant "
                    "variant and the actuators saturate at most --max-saturation of the time. Writes "
                    "tuned.yaml (only when a value works), tune.json and tune.png. Exit 0 when found, 1 "
                    "when no value in the range works, 2 on bad input.")
    tn.add_argument("scenario", help="a bundled scenario name or a YAML file")
    tn.add_argument("--gain", type=opt.gain_name, default="K",
                    help="K (default), Lambda, phi or rot_scale (pose and top_down tasks); params.NAME for a "
                         "plugin controller (with --range)")
    tn.add_argument("--range", type=opt.gain_range, default=None, metavar="LO,HI",
                    help="the search range (default: derived from the model at the start pose)")
    tn.add_argument("--variants", type=opt.variant_list, action=opt.Items,
                    default="nominal,mass_x0.7,mass_x1.5",
                    help="plant variants, comma-separated or repeated: nominal, mass_xF, payload_Mkg")
    tn.add_argument("--margin", type=opt.margin, default=2.0,
                    help="e(tf) ≤ 1 mm / M, hold ≤ 3 mm / M (default 2)")
    tn.add_argument("--max-saturation", type=opt.saturation_fraction, default=0.05,
                    help="largest fraction of the time an actuator may saturate (default 0.05)")
    _study_arguments(tn, "out/tune_NAME")
    tn.set_defaults(func=cmd_tune)


def _add_camera_parsers(sub) -> None:
    """study (camera, --filter-floor)."""
    st = sub.add_parser(
        "study", help="studies: camera (|e(tf)| against noise × latency × estimator)",
        description="camera: |e(tf)| on conveyor_pair_camera over noise × latency × estimator "
                    "(camera_study.md/.json, estimate.png). camera --filter-floor: the camera and "
                    "estimator alone (no arm) on a camera scenario, auto and a hand-set Kalman "
                    "filter per process noise: the "
                    "largest |estimate − true object| over each hold window, the error a controller "
                    "that follows the estimate inherits (filter_floor.md/.json).")
    st.add_argument("study", choices=["camera"])
    st.add_argument("--seeds", type=opt.count("--seeds"), default=10,
                    help="seeds per grid point (default 10)")
    st.add_argument("--workers", type=opt.count("--workers"), default=2,
                    help="worker processes (default 2)")
    st.add_argument("--out", help="output folder (default out/study_camera, with --filter-floor "
                                  "out/filter_floor_NAME)")
    st.add_argument("--quiet", action="store_true")
    st.add_argument("--filter-floor", action="store_true",
                    help="measure the camera + estimator alone (no arm): auto, and kalman_ca "
                         "(or --set measurement.estimator=kalman_cv) per process noise")
    st.add_argument("--scenario", help="with --filter-floor: a camera scenario (bundled name or YAML "
                                       "file with a camera; default curve_camera)")
    st.add_argument("--process-noise", metavar="Q,..", type=opt.process_noises, action=opt.Items,
                    help="with --filter-floor: process noises q > 0, comma-separated or repeated "
                         "(default 0.003,0.01,0.03,0.1,0.3)")
    st.add_argument("--set", action="append", metavar="KEY=VALUE",
                    help="with --filter-floor: " + SET_HELP)
    st.set_defaults(func=cmd_study)


def _add_bench_parser(sub) -> None:
    """bench: speed and accuracy as JSON (``studies.benchmark``), options checked like the others'."""
    from ptint_drake.studies.benchmark import BEFORE, CONFIGS  # noqa: PLC0415

    bench = sub.add_parser(
        "bench", help="speed/accuracy benchmark as JSON on stdout (docs/speed.md)",
        description="Speed and accuracy of the bundled scenarios (or the SCENARIOs) as JSON on stdout: per "
                    "scenario and configuration the realtime factor, integrator steps, derivative "
                    "evaluations, µs per evaluation and e(tf) next to a tight-tolerance reference run "
                    "(runge_kutta5, accuracy 1e-10). --schemes, --pair, --floors and --arms print their "
                    "studies instead. Progress on stderr; exit 0, 2 on bad input (docs/speed.md).")
    bench.add_argument("scenarios", nargs="*", type=opt.scenario_source, metavar="SCENARIO",
                       help="bundled scenario names or YAML files (default: every bundled scenario)")
    bench.add_argument("--configs", type=opt.bench_configs, action=opt.Items, default=",".join(CONFIGS),
                       help="configurations, comma-separated or repeated: default (fused, tanh), blocks "
                            "(the five wired blocks), sign (the paper's law) (default %(default)s)")
    bench.add_argument("--no-reference", action="store_true", help="skip the tight reference runs")
    bench.add_argument("--sweep", action="store_true",
                       help="also time a 3 x 3 sweep with 1 and 2 worker processes")
    bench.add_argument("--schemes", type=opt.integration_schemes, action=opt.Items, metavar="LIST",
                       help="scheme × accuracy table instead: integration schemes, comma-separated or "
                            "repeated (e.g. runge_kutta3,radau3)")
    bench.add_argument("--accuracies", type=opt.accuracies, action=opt.Items, default="1e-3,1e-4",
                       metavar="LIST", help="with --schemes: accuracies > 0, comma-separated or repeated "
                                            "(default %(default)s)")
    bench.add_argument("--simulator-extra", type=opt.yaml_mapping("--simulator-extra", inline=True),
                       default="", metavar="YAML",
                       help="with --schemes: more simulator fields, e.g. 'max_step_size: 0.02'")
    bench.add_argument("--pair", nargs=2, type=opt.yaml_mapping("--pair"), metavar=("A", "B"),
                       help=f"time two override mappings side by side (interleaved), e.g. '{{}}' '{BEFORE}'")
    bench.add_argument("--repeats", type=opt.count("--repeats"), default=5,
                       help="with --pair: pairs per scenario; with --floors: runs per diagram, at most 3 "
                            "(a pick scenario: alternated pairs, at least 5); with --arms: alternated "
                            "pairs per arm (default 5)")
    bench.add_argument("--arms", nargs="?", const="all", type=opt.bench_arms, metavar="LIST",
                       help="instead: each arm's curve realtime factor against a plain pydrake loop on the "
                            "same arm and integrator (a MultibodyPlant and a Python LeafSystem), and the "
                            "bound the package holds to; every bundled arm, or a comma-separated LIST "
                            "(rvm1, rvm1_5dof, rvm1_6dof, iiwa14, panda, ur5e)")
    bench.add_argument("--floors", action="store_true",
                       help="instead: µs per derivative evaluation of the plant with a C++ constant "
                            "actuation, with a do-nothing Python controller, and with the scenario's "
                            "controller (with a camera also the do-nothing controller fed by the "
                            "camera's estimates); a pick scenario: CPU s per simulated s of the run "
                            "and of the same station replaying its arm through Drake's C++ PD, and "
                            "their ratio")
    bench.set_defaults(func=cmd_bench)


def command_parser(name: str) -> argparse.ArgumentParser:
    """The parser of ``ptint NAME`` (a subcommand of ``make_parser``)."""
    return make_parser()._subparsers._group_actions[0].choices[name]


def _run(argv) -> int:
    """The command of ``argv``; its exit code, with bad input as one line (exit 2)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = make_parser().parse_args(argv)  # the option types check each value (cli.options)
        return args.func(args)
    except (ScenarioError, opt.OptionError) as exc:
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
    """``ptint ARGS`` (``sys.argv`` by default): the exit code; a closed stdout ends quietly."""
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


def console() -> int:
    """The ``ptint`` program (the console script and ``python -m ptint_drake``): ``main``, then
    every object alive is left out of the garbage collector's passes (``gc.freeze``), so that
    the interpreter's exit does not walk them again and again as it tears the modules down:
    with Drake, numba and matplotlib loaded that walk took 0.5-1.2 s of every command's
    wall time (0.06-0.14 s with the freeze).  Files are closed by then (every output is
    written through a context manager); only garbage in reference cycles is left unfinalized,
    which a process ending anyway does not need.  ``main`` itself, called in-process (tests,
    a notebook), leaves the collector alone."""
    code = main()
    gc.freeze()
    return code

