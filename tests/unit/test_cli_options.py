"""Option values checked by their argparse types (cli_options): parsed values, and a bad value
is one line ``ptint: error: FLAG: ...`` with exit 2 before any scenario is read."""

import pytest

from ptint_drake import cli
from ptint_drake.cli import options as cli_options


def parse(*argv):
    return cli.make_parser().parse_args(list(argv))


def test_values_arrive_parsed():
    args = parse("sweep", "x", "--beta", "0.5, 0.75,", "--tf", "1.2", "--workers", "3")
    assert args.beta == [0.5, 0.75] and args.tf == [1.2] and args.workers == 3
    defaults = parse("sweep", "x")
    assert defaults.beta == [0.25, 0.5, 0.75] and defaults.tf == [1.2, 1.5, 1.9]
    args = parse("robust", "x", "--range", "mass=0.5,2", "--range", "noise=0,1e-3", "--samples", "7")
    assert args.range == [("mass", (0.5, 2.0)), ("noise", (0.0, 1e-3))] and args.samples == 7
    args = parse("compare", "x", "--controllers", "pd,ptsmc", "--variants", "nominal,mass_x2")
    assert args.controllers == ["pd", "ptsmc"] and args.variants == ["nominal", "mass_x2"]
    args = parse("tune", "x", "--gain", "phi", "--margin", "3", "--max-saturation", "0")
    assert (args.gain, args.margin, args.max_saturation) == ("phi", 3.0, 0.0)
    assert parse("tune", "x").variants == ["nominal", "mass_x0.7", "mass_x1.5"]
    args = parse("study", "camera", "--filter-floor", "--process-noise", "0.01,0.1")
    assert args.process_noise == [0.01, 0.1]


BAD = [
    (("sweep", "x", "--beta", "0.5,1"), "--beta: every value must be in (0, 1), got 1.0"),
    (("sweep", "x", "--tf", "1.5,nan"), "--tf: every value must be > 0, got nan"),
    (("sweep", "x", "--tf", ","), "--tf: no values given"),
    (("sweep", "x", "--workers", "0"), "--workers: must be >= 1, got 0"),
    (("robust", "x", "--samples", "0"), "--samples: must be >= 1, got 0"),
    (("robust", "x", "--range", "mass=2,1"),
     "--range mass: expected LOW,HIGH with 0 <= LOW <= HIGH, got '2,1'"),
    (("robust", "x", "--range", "speed=0,1"), "--range: unknown parameter 'speed' (one of mass, "),
    (("compare", "x", "--controllers", "ptsmc,lqr"), "--controllers: unknown 'lqr' (one of ptsmc, "),
    (("compare", "x", "--variants", " , "), "--variants: no values given"),
    (("tune", "x", "--gain", "k"),
     "--gain: must be one of K, Lambda, phi, rot_scale or params.NAME, got 'k'"),
    (("tune", "x", "--range", "2,1"), "--range: expected LO,HI with 0 < LO < HI, got '2,1'"),
    (("tune", "x", "--margin", "0.5"), "--margin: must be >= 1, got 0.5"),
    (("tune", "x", "--max-saturation", "1.5"), "--max-saturation: must be in [0, 1], got 1.5"),
    (("study", "camera", "--seeds", "0"), "--seeds: must be >= 1, got 0"),
    (("study", "camera", "--filter-floor", "--process-noise", "inf"),
     "--process-noise: every value must be > 0 and finite, got inf"),
]


@pytest.mark.parametrize("argv, message", BAD, ids=[" ".join(a[2:]) for a, _ in BAD])
def test_a_bad_value_fails_in_its_parser(argv, message):
    with pytest.raises(cli_options.OptionError) as err:
        parse(*argv)
    assert str(err.value).startswith(message), str(err.value)


@pytest.mark.parametrize("argv, message", BAD[:4], ids=[" ".join(a[2:]) for a, _ in BAD[:4]])
def test_main_prints_it_as_one_line_exit_2(capsys, argv, message):
    # the scenario "x" does not exist: the option is reported first, as before
    assert cli.main(list(argv)) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ptint: error: {message}") and err.count("\n") == 1, err


def test_a_list_option_is_comma_separated_repeated_or_both():
    """Every list option (``cli_options.Items``): the first use replaces the default, each use
    adds its items, an item given twice counts once."""
    args = parse("sweep", "x", "--beta", "0.5", "--beta", "0.25,0.5", "--tf", "1.2,1.5")
    assert args.beta == [0.5, 0.25] and args.tf == [1.2, 1.5]
    args = parse("compare", "x", "--controllers", "pd", "--controllers", "ptsmc", "--variants", "nominal")
    assert args.controllers == ["pd", "ptsmc"] and args.variants == ["nominal"]


def test_bench_is_a_command_of_the_main_parser():
    """``ptint bench`` parses like the other commands (it handed its arguments to a parser of its
    own before): lists arrive split, comma-separated or repeated, and checked."""
    defaults = parse("bench")
    assert (defaults.scenarios, defaults.configs, defaults.accuracies, defaults.repeats) == (
        [], ["default", "blocks", "sign"], [1e-3, 1e-4], 5)
    assert defaults.schemes is None and defaults.pair is None and defaults.simulator_extra == ""
    args = parse("bench", "--configs", "default,sign", "--configs", "blocks", "--schemes", "runge_kutta3",
                 "--schemes", "radau3,runge_kutta3", "--accuracies", "1e-4", "--simulator-extra",
                 "max_step_size: 0.02", "--pair", "{}", "controller: {K: 40}", "--repeats", "2",
                 "curve_b075_tf15", "assembly")
    assert args.configs == ["default", "sign", "blocks"] and args.schemes == ["runge_kutta3", "radau3"]
    assert args.accuracies == [1e-4] and args.simulator_extra == "max_step_size: 0.02"
    assert args.pair == ["{}", "controller: {K: 40}"] and args.repeats == 2
    assert args.scenarios == ["curve_b075_tf15", "assembly"] and args.func is cli.cmd_bench


def test_bench_help_lists_every_option():
    text = cli.command_parser("bench").format_help()
    for option in ("SCENARIO", "--configs", "--no-reference", "--sweep", "--schemes", "--accuracies",
                   "--simulator-extra", "--pair A B", "--repeats", "--floors"):
        assert option in text, option
    assert "bench" in cli.make_parser().format_help()


BAD_BENCH = [
    (("bench", "--configs", "default,fast"), "--configs: unknown 'fast' (one of default, blocks, sign)"),
    (("bench", "--schemes", "runge_kutta3", "--schemes", "rk3"), "--schemes: unknown 'rk3' (one of "),
    (("bench", "--accuracies", "1e-4,0"), "--accuracies: every value must be > 0 and finite, got 0"),
    (("bench", "--repeats", "0"), "--repeats: must be >= 1, got 0"),
    (("bench", "--pair", "{}", "[1, 2]"), "--pair: expected a YAML mapping, got '[1, 2]'"),
    (("bench", "--simulator-extra", "max_step_size: ["), "--simulator-extra: expected FIELD: VALUE"),
    (("bench", "curve_b075_tf15", "no_such"), "scenario: 'no_such' is neither a bundled scenario"),
]


@pytest.mark.parametrize("argv, message", BAD_BENCH, ids=[" ".join(a[1:]) for a, _ in BAD_BENCH])
def test_a_bad_bench_option_is_one_line_naming_it_exit_2(capsys, argv, message):
    """Checked when parsed: nothing is simulated (``benchmark.from_options`` is never called)."""
    with pytest.raises(cli_options.OptionError) as err:
        parse(*argv)
    assert str(err.value).startswith(message), str(err.value)
    assert cli.main(list(argv)) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"ptint: error: {message}") and err.count("\n") == 1, err


def test_bench_hands_the_parsed_lists_to_the_benchmark(monkeypatch, capsys):
    from ptint_drake.studies import benchmark

    calls = {}
    monkeypatch.setattr(benchmark, "scheme_table", lambda *a: calls.setdefault("schemes", a) and "s")
    monkeypatch.setattr(benchmark, "paired", lambda *a: calls.setdefault("paired", a) and "p")
    monkeypatch.setattr(benchmark, "benchmark", lambda *a, **k: {"configs": a[1], "reference": a[2]})
    assert cli.main(["bench", "--schemes", "radau3", "--accuracies", "1e-3", "--accuracies", "1e-5",
                     "--pair", "{}", "{}", "--repeats", "3", "curve_b075_tf12"]) == 0
    assert calls["schemes"][:4] == (["curve_b075_tf12"], ["radau3"], [1e-3, 1e-5], "")
    assert calls["paired"][:4] == (["curve_b075_tf12"], "{}", "{}", 3)
    assert '"schemes": "s"' in capsys.readouterr().out
    assert cli.main(["bench", "--configs", "sign", "--no-reference"]) == 0
    assert '"configs": [\n    "sign"\n  ],\n  "reference": false' in capsys.readouterr().out


def test_a_value_that_is_no_number_keeps_argparses_message(capsys):
    with pytest.raises(SystemExit) as stop:
        cli.main(["tune", "x", "--margin", "two"])
    assert stop.value.code == 2
    assert "argument --margin: invalid float value: 'two'" in capsys.readouterr().err


def test_the_program_leaves_its_heap_out_of_the_exit_collections(monkeypatch, capsys):
    """``console`` (the ``ptint`` program) returns ``main``'s exit code with every live object
    frozen (the interpreter's exit then skips them); ``main`` alone, as tests and notebooks
    call it, freezes nothing."""
    import gc

    monkeypatch.setattr("sys.argv", ["ptint", "list"])
    gc.unfreeze()
    try:
        assert cli.main(["list"]) == 0 and gc.get_freeze_count() == 0
        assert cli.console() == 0
        assert gc.get_freeze_count() > 1000
    finally:
        gc.unfreeze()
    assert "curve_b075_tf15" in capsys.readouterr().out
    monkeypatch.setattr("sys.argv", ["ptint", "run", "no_such_scenario"])
    assert cli.console() == 2  # an error keeps its exit code
    gc.unfreeze()


def test_a_missed_line_suggests_tune_only_where_the_world_can_be_tuned():
    """A catch's miss (closed on nothing) is not the gains': no ``ptint tune`` in its line; an
    interception's miss keeps the hint (``runs.missed_line``, ``World.tune_refusal``)."""
    from ptint_drake.cli.runs import missed_line
    from ptint_drake.simulation.scenario import LoadedScenario

    missed = {"reasons": ["not caught: closed on nothing"]}
    catch = LoadedScenario.load("catch_toss_iiwa14").scenario
    assert missed_line(catch, missed, "catch_toss_iiwa14") == \
        "catch_toss_iiwa14: MISSED (not caught: closed on nothing)"
    curve = LoadedScenario.load("curve_b075_tf15").scenario
    assert "try `ptint tune curve_b075_tf15`" in missed_line(curve, {"reasons": ["late"]}, "curve_b075_tf15")
