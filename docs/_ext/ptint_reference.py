"""The documentation pages generated from the code, so that they cannot drift from it.

- ``cli_markdown()``: the command-line reference, read from ``ptint_drake.cli.make_parser()``
  (every subcommand, its usage, description and options), i.e. what ``ptint --help`` and
  ``ptint CMD --help`` print.
- ``schema_markdown()``: the scenario schema, one row per field of ``scenario.Scenario`` and
  its nested dataclasses (Drake's ``SimulatorConfig`` through its ``__fields__``), with the
  type, the default and the comment written beside the field in the source.

``write_generated(folder)`` writes both into ``folder`` (``docs/_generated``, not committed);
``docs/conf.py`` calls it at every build and the pages include the files.
``tests/unit/test_docs.py`` checks both against the parser and the dataclasses.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import re
import typing
from pathlib import Path

SUPPRESS = argparse.SUPPRESS


def _subparsers(parser: argparse.ArgumentParser) -> dict:
    """The subcommands of ``parser``: name → its parser, in the order of ``--help``."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def command_parsers() -> dict:
    """Every ``ptint`` command → the parser that reads its arguments (``bench`` included: one
    parser for every command)."""
    from ptint_drake.cli import make_parser

    return _subparsers(make_parser())


def options(parser: argparse.ArgumentParser) -> list:
    """The documented arguments of ``parser``: (option strings or the positional's name,
    metavar, default, help) per argument, ``--help`` included."""
    rows = []
    for action in parser._actions:
        if action.help == SUPPRESS or isinstance(action, argparse._SubParsersAction):
            continue
        names = ", ".join(action.option_strings) or action.dest
        if action.choices and not action.option_strings:
            names = "{" + ",".join(map(str, action.choices)) + "}"
        metavar = ""
        if action.option_strings and action.nargs != 0:
            metavar = action.metavar or action.dest.upper()
        default = action.default
        if default in (None, False, SUPPRESS) or action.nargs == 0:
            default = ""
        text = (action.help or "").replace("%(default)s", str(action.default))
        rows.append((names, metavar, default, text))
    return rows


def _cell(text) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def _options_table(parser: argparse.ArgumentParser) -> list:
    lines = ["| argument | value | default | meaning |", "|---|---|---|---|"]
    for names, metavar, default, text in options(parser):
        value = f"`{_cell(metavar)}`" if metavar else ""
        shown = f"`{_cell(default)}`" if default != "" else ""
        lines.append(f"| `{_cell(names)}` | {value} | {shown} | {_cell(text)} |")
    return lines


def cli_markdown() -> str:
    """The command-line reference as MyST Markdown (see the module docstring)."""
    from ptint_drake.cli import make_parser

    top = make_parser()
    out = ["## `ptint`", "", "```text", top.format_usage().strip(), "```", "",
           _cell(top.description or ""), "", *_options_table(top), "",
           "Commands: " + ", ".join(f"`{n}`" for n in command_parsers()) + ".", ""]
    helps = {a.dest: a.help for a in next(a for a in top._actions
                                          if isinstance(a, argparse._SubParsersAction))._choices_actions}
    for name, parser in command_parsers().items():
        out += [f"## `ptint {name}`", ""]
        if helps.get(name):
            out += [f"*{_cell(helps[name])}*", ""]
        out += ["```text", parser.format_usage().strip(), "```", ""]
        if parser.description:
            out += [_cell(parser.description), ""]
        out += [*_options_table(parser), ""]
        if parser.epilog:
            out += [_cell(parser.epilog), ""]
    return "\n".join(out)


def _type_name(tp) -> str:
    if isinstance(tp, str):
        return tp
    origin = typing.get_origin(tp)
    if origin is typing.Union:
        args = [a for a in typing.get_args(tp) if a is not type(None)]
        return " | ".join(_type_name(a) for a in args) + (" or null" if len(args) < len(typing.get_args(tp))
                                                          else "")
    if origin in (list, typing.List):
        return f"list[{', '.join(_type_name(a) for a in typing.get_args(tp))}]"
    if origin in (dict, typing.Dict):
        return f"dict[{', '.join(_type_name(a) for a in typing.get_args(tp))}]"
    return getattr(tp, "__name__", str(tp))


def _comments(cls) -> dict:
    """field name → the ``# comment`` written after it in ``cls``'s source (empty if none): after
    ``name: type = default`` in a class body, or after ``("name", type, field(...)),`` in the
    module of a class made by ``make_dataclass`` (which has no class body to read)."""
    try:
        source = inspect.getsource(cls)
        pattern = r"^\s+(\w+): [^\n#]*?(?:#\s*(.*))?$"
    except (OSError, TypeError):
        if not dataclasses.is_dataclass(cls):
            return {}
        try:
            source = inspect.getsource(inspect.getmodule(cls))
        except (OSError, TypeError):
            return {}
        names = "|".join(sorted(f.name for f in dataclasses.fields(cls)))
        pattern = r'^\s+\("(' + names + r')", [^\n#]*?(?:#\s*(.*))?$'
    found = {}
    for m in re.finditer(pattern, source, re.M):
        if m.group(2):
            found.setdefault(m.group(1), m.group(2).strip())
    return found


def _nested(tp):
    """The dataclass (or Drake config class with ``__fields__``) inside ``tp``, if any."""
    for candidate in (tp, *typing.get_args(tp)):
        if dataclasses.is_dataclass(candidate) or hasattr(candidate, "__fields__"):
            return candidate
        inner = typing.get_args(candidate)
        if inner and (dataclasses.is_dataclass(inner[0]) or hasattr(inner[0], "__fields__")):
            return inner[0]
    return None


def _default(cls, name: str):
    try:
        value = getattr(cls(), name)
    except Exception:  # noqa: BLE001  (a class that cannot be built empty: no default shown)
        return ""
    if dataclasses.is_dataclass(value) or hasattr(type(value), "__fields__"):
        return ""
    return "" if value is None else repr(value)


def schema_fields(cls=None, prefix: str = "") -> list:
    """Every field of the scenario schema, depth first: (path, type, default, comment).  A list of
    mappings is written ``interceptions[]``; Drake's ``SimulatorConfig`` through its ``__fields__``."""
    from ptint_drake.simulation.scenario import Scenario

    cls = Scenario if cls is None else cls
    rows = []
    if dataclasses.is_dataclass(cls):
        hints = typing.get_type_hints(cls)
        fields = [(f.name, hints.get(f.name, f.type)) for f in dataclasses.fields(cls)]
    else:  # a Drake config class (SimulatorConfig)
        fields = [(f.name, f.type) for f in cls.__fields__]
    comments = {}
    for base in reversed(inspect.getmro(cls)) if inspect.isclass(cls) else ():
        comments.update(_comments(base))
    for name, tp in fields:
        path = f"{prefix}{name}"
        nested = _nested(tp)
        is_list = typing.get_origin(tp) in (list, typing.List)
        rows.append((path + ("[]" if is_list and nested else ""), _type_name(tp) if not nested else
                     ("list of mappings" if is_list else "mapping") +
                     (" or null" if type(None) in typing.get_args(tp) else ""),
                     _default(cls, name), comments.get(name, "")))
        if nested is not None:
            rows += schema_fields(nested, f"{path}{'[]' if is_list else ''}.")
    return rows


def schema_markdown() -> str:
    """The scenario schema as a MyST Markdown table (see ``schema_fields``)."""
    lines = ["| field | type | default | meaning |", "|---|---|---|---|"]
    for path, tp, default, comment in schema_fields():
        shown = f"`{_cell(default)}`" if default else ""
        lines.append(f"| `{path}` | {_cell(tp)} | {shown} | {_cell(comment)} |")
    return "\n".join(lines) + "\n"


def write_generated(folder: Path) -> None:
    """Write ``cli.md`` and ``schema.md`` into ``folder`` (only when their text changed)."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in (("cli.md", cli_markdown()), ("schema.md", schema_markdown())):
        path = folder / name
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
