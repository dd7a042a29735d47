"""The documentation site's generated pages match the code: the command-line reference lists
exactly the commands and options that ``ptint --help`` and ``ptint CMD --help`` print, the
scenario page lists every field of the schema's dataclasses (Drake's ``SimulatorConfig``
included), and every public module, class and function of the package has a docstring (what
the API reference shows)."""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re
import sys
import typing
from pathlib import Path

import pytest

import ptint_drake

DOCS = Path(__file__).resolve().parents[2] / "docs"
sys.path.insert(0, str(DOCS / "_ext"))
import ptint_reference  # noqa: E402

OPTION = re.compile(r"(?<![\w-])(--?[a-zA-Z][\w-]*)")


def help_options(text: str) -> set:
    """The option strings in a ``--help`` text's option lists (not in its prose)."""
    found = set()
    for line in text.splitlines():
        if re.match(r"^\s{2}-", line):  # an option line: "  -h, --help ..." / "  --out OUT ..."
            head = re.split(r"\s{2,}", line.strip())[0]
            found |= set(OPTION.findall(head))
    return found


def page_sections(markdown: str) -> dict:
    """The CLI page's sections: command ('' for ptint itself) → its text."""
    parts = re.split(r"^## `ptint ?([\w]*)`$", markdown, flags=re.M)
    return {parts[i]: parts[i + 1] for i in range(1, len(parts), 2)}


def page_options(section: str) -> set:
    rows = [line.split("|")[1] for line in section.splitlines() if line.startswith("| `")]
    return {o for row in rows for o in OPTION.findall(row)}


def test_cli_page_lists_exactly_what_help_prints():
    from ptint_drake.cli import make_parser

    top = make_parser()
    commands = re.search(r"\{([\w,]+)\}", top.format_usage()).group(1).split(",")
    sections = page_sections(ptint_reference.cli_markdown())
    assert list(sections) == ["", *commands]
    assert page_options(sections[""]) == help_options(top.format_help())
    subparsers = next(a for a in top._actions if a.__class__.__name__ == "_SubParsersAction").choices
    for name in commands:
        parser = subparsers[name]
        expected = help_options(parser.format_help())
        assert expected, name
        assert page_options(sections[name]) == expected, name


def _fields(cls, prefix=""):
    """The schema's field paths, walked independently of the page's generator."""
    if dataclasses.is_dataclass(cls):
        hints = typing.get_type_hints(cls)
        items = [(f.name, hints[f.name]) for f in dataclasses.fields(cls)]
    else:
        items = [(f.name, f.type) for f in cls.__fields__]
    for name, tp in items:
        inner = [a for a in (tp, *typing.get_args(tp)) if dataclasses.is_dataclass(a)
                 or hasattr(a, "__fields__")]
        is_list = typing.get_origin(tp) is list
        listed = typing.get_args(tp)[0] if is_list else None
        if listed is not None and dataclasses.is_dataclass(listed):
            yield f"{prefix}{name}[]"
            yield from _fields(listed, f"{prefix}{name}[].")
        elif inner:
            yield f"{prefix}{name}"
            yield from _fields(inner[0], f"{prefix}{name}.")
        else:
            yield f"{prefix}{name}"


def test_scenario_page_lists_every_field():
    from pydrake.systems.analysis import SimulatorConfig

    from ptint_drake.simulation.scenario import Scenario

    page = ptint_reference.schema_markdown()
    listed = set(re.findall(r"^\| `([^`]+)`", page, re.M))
    expected = set(_fields(Scenario))
    assert expected == listed
    assert {f"simulator.{f.name}" for f in SimulatorConfig.__fields__} <= listed
    assert {"interceptions[].target.ballistic.release", "measurement.latency", "criteria.e_tf",
            "controller.pd.Kp"} <= listed


def _modules():
    for info in pkgutil.walk_packages(ptint_drake.__path__, "ptint_drake."):
        if not info.name.rsplit(".", 1)[-1].startswith("_") or info.name.endswith("__init__"):
            yield importlib.import_module(info.name)


def undocumented() -> list:
    """Public modules, and classes and functions defined in them, without a docstring."""
    missing = []
    for module in [ptint_drake, *_modules()]:
        if not (module.__doc__ or "").strip():
            missing.append(module.__name__)
        for name, obj in vars(module).items():
            if name.startswith("_") or getattr(obj, "__module__", None) != module.__name__:
                continue
            if (inspect.isclass(obj) or inspect.isfunction(obj)) and not (obj.__doc__ or "").strip():
                missing.append(f"{module.__name__}.{name}")
    return missing


def test_every_public_name_has_a_docstring():
    assert undocumented() == []


@pytest.mark.parametrize("text, options", [("  -h, --help  show\n  --out OUT   folder (--x)\n",
                                            {"-h", "--help", "--out"})])
def test_help_options_reads_option_lines_only(text, options):
    assert help_options(text) == options
