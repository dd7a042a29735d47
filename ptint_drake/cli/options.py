"""The command line's option values: each option's parser and check in one argparse ``type=``.

A value that fails its check raises ``OptionError``, which ``cli.main`` prints as the one line
``ptint: error: FLAG: ...`` (exit 2), the form of every other bad input; a value of the wrong
type (``--workers abc``) keeps argparse's own message and usage.  Each parser returns the
value the command uses (a list of floats, a (name, (low, high)) pair, ...).  A list option
takes ``action=Items``: comma-separated (``--configs default,sign``), repeated (``--configs
default --configs sign``) or both.  ``out_folder`` checks an ``--out`` folder (the file system,
not the text, decides).
"""

from __future__ import annotations

import argparse
import functools
import math
from collections.abc import Callable
from pathlib import Path

from ptint_drake.simulation.scenario import ScenarioError


class OptionError(Exception):
    """An option value that fails its check; the message starts with the flag.  Not a
    ValueError: argparse would turn that into its own "invalid ... value" message."""


class Items(argparse.Action):
    """A list option (its type parses comma-separated text into a list): each use adds its items,
    the first replaces the default, an item given twice counts once."""

    def __call__(self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, values: list,
                 option_string: str | None = None) -> None:
        current = getattr(namespace, self.dest, None)
        if current is None or current is self.default:  # the first use replaces the default
            current = []
        setattr(namespace, self.dest, list(dict.fromkeys([*current, *values])))


def _option(parse):
    """``parse`` (raising ScenarioError naming the flag) as an argparse type."""
    @functools.wraps(parse)
    def checked(text: str):
        try:
            return parse(text)
        except ScenarioError as exc:
            raise OptionError(str(exc)) from None
    return checked


def _number(kind, text: str):
    """``kind(text)``, or argparse's own message for a value that is not a number."""
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid {kind.__name__} value: {text!r}") from None


def floats(text: str, flag: str) -> list[float]:
    """Comma-separated numbers (``0.25,0.5``); empty items are skipped, none at all is an error."""
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise ScenarioError(f"{flag}: expected comma-separated numbers, got {text!r}") from None
    if not values:
        raise ScenarioError(f"{flag}: no values given")
    return values


def names(text: str, flag: str, allowed=None) -> list[str]:
    """Comma-separated names; ScenarioError naming an item not in ``allowed`` (if given)."""
    items = [v.strip() for v in text.split(",") if v.strip()]
    if not items:
        raise ScenarioError(f"{flag}: no values given")
    for item in items:
        if allowed is not None and item not in allowed:
            raise ScenarioError(f"{flag}: unknown {item!r} (one of {', '.join(allowed)})")
    return items


@_option
def betas(text: str) -> list[float]:
    """``--beta``: TBG shapes β in (0, 1) (paper eq. 6)."""
    values = floats(text, "--beta")
    for b in values:
        if not 0.0 < b < 1.0:
            raise ScenarioError(f"--beta: every value must be in (0, 1), got {b}")
    return values


@_option
def final_times(text: str) -> list[float]:
    """``--tf``: prescribed times in s, each > 0."""
    values = floats(text, "--tf")
    for tf in values:
        if not tf > 0.0:
            raise ScenarioError(f"--tf: every value must be > 0, got {tf}")
    return values


@_option
def process_noises(text: str) -> list[float]:
    """``--process-noise``: the Kalman filter's process noises q, each > 0 and finite."""
    return positive_floats(text, "--process-noise")


def positive_floats(text: str, flag: str) -> list[float]:
    """Comma-separated numbers, each > 0 and finite (ScenarioError naming ``flag`` otherwise)."""
    values = floats(text, flag)
    for q in values:
        if not (q > 0.0 and q != math.inf):  # NaN fails the first test
            raise ScenarioError(f"{flag}: every value must be > 0 and finite, got {q:g}")
    return values


def count(flag: str) -> Callable[[str], int]:
    """An argparse type for a count ``flag`` (``--workers``, ``--samples``, ``--seeds``): an int >= 1."""
    def parse(text: str) -> int:
        value = _number(int, text)
        if value < 1:
            raise OptionError(f"{flag}: must be >= 1, got {value}")
        return value
    return parse


def _converted(kind, text: str, flag: str, expected: str):
    """``kind(text)``, or OptionError naming ``flag`` and what it ``expected``."""
    try:
        return kind(text)
    except ValueError:
        raise OptionError(f"{flag}: expected {expected}, got {text!r}") from None


def seconds(flag: str, allow_zero: bool = False) -> Callable[[str], float]:
    """An argparse type: a finite time in s, > 0 (or >= 0 with ``allow_zero``)."""
    def parse(text: str) -> float:
        value = _converted(float, text, flag, "a number of seconds")
        if not (math.isfinite(value) and (value >= 0 if allow_zero else value > 0)):
            raise OptionError(f"{flag}: must be {'>= 0' if allow_zero else '> 0'} and finite, got {text}")
        return value
    return parse


def fraction(flag: str, top_open: bool = True) -> Callable[[str], float]:
    """An argparse type: a number in [0, 1) (``top_open``) or (0, 1]."""
    def parse(text: str) -> float:
        value = _converted(float, text, flag, "a number")
        ok = 0.0 <= value < 1.0 if top_open else 0.0 < value <= 1.0
        if not ok:
            raise OptionError(f"{flag}: must be in {'[0, 1)' if top_open else '(0, 1]'}, got {text}")
        return value
    return parse


def integer_in(flag: str, low: int, high: int) -> Callable[[str], int]:
    """An argparse type: an integer in [``low``, ``high``] (e.g. ``--priority``, 0-99)."""
    def parse(text: str) -> int:
        value = _converted(int, text, flag, f"an integer {low}-{high}")
        if not low <= value <= high:
            raise OptionError(f"{flag}: must be in {low}-{high}, got {text}")
        return value
    return parse


@_option
def robust_range(pair: str) -> tuple[str, tuple[float, float]]:
    """``--range NAME=LOW,HIGH`` of ``robust``: (NAME, (LOW, HIGH)) with 0 <= LOW <= HIGH (LOW < 0
    allowed for the signed ranges, close_jitter and part_lateral)."""
    from ptint_drake.studies.robust import RANGES, SIGNED  # noqa: PLC0415

    key, _, value = pair.partition("=")
    if key not in RANGES:
        raise ScenarioError(f"--range: unknown parameter {key!r} (one of {', '.join(RANGES)})")
    lo_hi = floats(value, f"--range {key}")
    if len(lo_hi) != 2 or lo_hi[0] > lo_hi[1] or (lo_hi[0] < 0 and key not in SIGNED):
        bound = "LOW <= HIGH" if key in SIGNED else "0 <= LOW <= HIGH"
        raise ScenarioError(f"--range {key}: expected LOW,HIGH with {bound}, got {value!r}")
    return key, (lo_hi[0], lo_hi[1])


@_option
def ranges_preset(text: str) -> str:
    """``--ranges`` of ``robust``: the name of a preset of ranges (``studies.robust.PRESETS``)."""
    from ptint_drake.studies.robust import PRESETS  # noqa: PLC0415

    if text not in PRESETS:
        raise ScenarioError(f"--ranges: unknown preset {text!r} (one of {', '.join(PRESETS)})")
    return text


@_option
def controller_list(text: str) -> list[str]:
    """``--controllers`` of ``compare``: registered controllers and plugins' ``module:Class``."""
    from ptint_drake.controllers import CONTROLLERS, known_type, plugin  # noqa: PLC0415

    items = names(text, "--controllers")
    for item in items:
        if not known_type(item):
            raise ScenarioError(f"--controllers: unknown {item!r} (one of {', '.join(CONTROLLERS)}, "
                                f"or {plugin.FORM})")
    return items


@_option
def variant_list(text: str) -> list[str]:
    """``--variants``: plant variant names (``scenario.apply_variant`` checks each one once
    the scenario is loaded)."""
    return names(text, "--variants")


@_option
def gain_name(text: str) -> str:
    """``--gain`` of ``tune``: one of ``tune.GAINS``, or ``params.NAME`` of a plugin controller
    (which needs ``--range``: checked once the command has every option)."""
    from ptint_drake.studies.tune import GAINS, PARAM_PREFIX  # noqa: PLC0415

    if text.startswith(PARAM_PREFIX) and text[len(PARAM_PREFIX):].isidentifier():
        return text
    if text not in GAINS:
        raise ScenarioError(f"--gain: must be one of {', '.join(GAINS)} or params.NAME, got {text!r}")
    return text


@_option
def gain_range(text: str) -> tuple[float, float]:
    """``--range LO,HI`` of ``tune``: the search range instead of the model-derived one."""
    values = floats(text, "--range")
    if len(values) != 2 or not 0.0 < values[0] < values[1]:
        raise ScenarioError(f"--range: expected LO,HI with 0 < LO < HI, got {text!r}")
    return values[0], values[1]


def margin(text: str) -> float:
    """``--margin`` of ``tune``: the criteria are divided by it, so >= 1."""
    value = _number(float, text)
    if not value >= 1.0:
        raise OptionError(f"--margin: must be >= 1, got {value}")
    return value


def saturation_fraction(text: str) -> float:
    """``--max-saturation`` of ``tune``: a fraction of the time, in [0, 1]."""
    value = _number(float, text)
    if not 0.0 <= value <= 1.0:
        raise OptionError(f"--max-saturation: must be in [0, 1], got {value}")
    return value


@_option
def scenario_source(text: str) -> str:
    """A scenario argument checked when parsed (``bench``'s list): a bundled name or a file."""
    from ptint_drake.simulation.scenario import scenario_text  # noqa: PLC0415

    scenario_text(text)  # ScenarioError: "scenario: 'x' is neither a bundled scenario ... nor a file"
    return text


@_option
def bench_configs(text: str) -> list[str]:
    """``--configs`` of ``bench``: names of ``benchmark.CONFIGS``."""
    from ptint_drake.studies.benchmark import CONFIGS  # noqa: PLC0415

    return names(text, "--configs", list(CONFIGS))


@_option
def bench_arms(text: str) -> list[str]:
    """``--arms`` of ``bench``: names of ``arm_bench.ARM_CURVES`` (the bundled arms), or ``all``."""
    from ptint_drake.studies.arm_bench import ARM_CURVES  # noqa: PLC0415

    return list(ARM_CURVES) if text.strip() == "all" else names(text, "--arms", list(ARM_CURVES))


@_option
def integration_schemes(text: str) -> list[str]:
    """``--schemes`` of ``bench``: Drake's integration schemes (``GetIntegrationSchemes``)."""
    from pydrake.systems.analysis import GetIntegrationSchemes  # noqa: PLC0415

    return names(text, "--schemes", GetIntegrationSchemes())


@_option
def accuracies(text: str) -> list[float]:
    """``--accuracies`` of ``bench``: integrator accuracies, each > 0."""
    return positive_floats(text, "--accuracies")


def yaml_mapping(flag: str, inline: bool = False) -> Callable[[str], str]:
    """An argparse type for YAML mapping text (``--pair``: ``'controller: {K: 40}'``); with
    ``inline`` the fields that go inside a flow mapping's braces (``--simulator-extra``:
    ``'max_step_size: 0.02'``).  The text itself is the value."""
    def parse(text: str) -> str:
        import yaml  # noqa: PLC0415

        try:
            tree = yaml.safe_load("{" + text + "}" if inline else text)
        except yaml.YAMLError:
            tree = []
        if tree is not None and not isinstance(tree, dict):
            form = "FIELD: VALUE, .. (the fields inside {})" if inline else "a YAML mapping"
            raise OptionError(f"{flag}: expected {form}, got {text!r}")
        return text
    return parse


def out_folder(value, default: Path) -> Path:
    """The ``--out`` folder (``default`` without one); ScenarioError if it or a parent is a file."""
    out = Path(value) if value else default
    for p in (out, *out.parents):
        if p.exists():
            if not p.is_dir():
                raise ScenarioError(f"--out: {p} is a file" if p == out
                                    else f"--out: {p} (in {out}) is a file")
            break
    return out


def scenario_and_out(args: argparse.Namespace, prefix: str = "", name_or_file: str | None = None):
    """(``LoadedScenario``, output folder) of a command: the scenario argument (or
    ``name_or_file``) with its ``--set`` overrides, parsed once, and ``--out`` or
    out/PREFIXNAME.  An ``--out`` that is a file fails before the scenario is read."""
    from ptint_drake.simulation.scenario import LoadedScenario  # noqa: PLC0415

    out_folder(args.out, Path("out"))
    loaded = LoadedScenario.load(name_or_file or args.scenario, args.set)
    return loaded, out_folder(args.out, Path("out") / f"{prefix}{loaded.scenario.name}")
