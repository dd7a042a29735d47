"""Scenario YAML in and out: overrides, portable dumps, one-line messages that name the field.

``override_text`` applies ``--set key=value`` overrides (dotted paths with list items,
values as YAML) to a scenario's YAML text, the one override mechanism of the command line,
scripts and tests (``scenario.LoadedScenario`` parses the result); ``dump_yaml`` writes a
scenario with Drake's ``yaml_dump_typed`` so that ``scenario.parse_scenario`` reads it back
to the same scenario, under any supported Drake; ``yaml_error`` turns a failed
``yaml_load_typed`` into one line naming the first field that does not fit the schema.
"""

import dataclasses
import re
import types
import typing
from typing import List, Optional

from pydrake.common.yaml import yaml_dump_typed
from pydrake.multibody.plant import MultibodyPlantConfig
from pydrake.systems.analysis import SimulatorConfig

from ptint_drake.config.errors import ScenarioError

# SimulatorConfig fields that only some supported Drake versions have, each with the value that
# means the same as leaving it out (Drake 1.52 removed publish_every_time_step; false was the default).
_VERSION_SPECIFIC_SIMULATOR = {"publish_every_time_step": False}


_PATH_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]|(\.)")
_NUMBER_WITH_EXPONENT = re.compile(r"^[-+]?(?:[0-9][0-9_]*)?(?:\.[0-9_]*)?[eE][-+]?[0-9]+$")


def _path_error(key: str) -> ScenarioError:
    return ScenarioError(f"--set {key}: not a field path (expected e.g. controller.K or interceptions[0].tf)")


def split_path(key: str) -> list:
    """``interceptions[1].target.linear.velocity`` → ``['interceptions', 1, 'target', ...]``:
    names joined by dots, list indices in brackets; ScenarioError naming ``key`` otherwise."""
    parts, pos, expect_name = [], 0, True
    while pos < len(key):
        m = _PATH_TOKEN.match(key, pos)
        if m is None or (m.group(1) and not expect_name) or ((m.group(2) or m.group(3)) and expect_name):
            raise _path_error(key)
        if m.group(1):
            parts.append(m.group(1))
        elif m.group(2):
            parts.append(int(m.group(2)))
        expect_name = bool(m.group(3))
        pos = m.end()
    if not parts or expect_name:
        raise _path_error(key)
    return parts


def _path_text(parts) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else (f".{p}" if i else p)
                   for i, p in enumerate(parts))


def set_path(tree: dict, key: str, value) -> None:
    """Set ``value`` at the path ``key`` (dots and ``[i]``) in the plain YAML data ``tree``;
    missing mappings on the way are created, a list item must exist."""
    parts = split_path(key)
    node = tree
    for depth, part in enumerate(parts):
        here = _path_text(parts[:depth]) or "the scenario"
        if isinstance(part, int):
            if not isinstance(node, list):
                raise ScenarioError(f"--set {key}: {here} is not a list, it cannot be indexed")
            if part >= len(node):
                raise ScenarioError(f"--set {key}: index {part} out of range ({here} has "
                                    f"{len(node)} item{'s' if len(node) != 1 else ''})")
        elif not isinstance(node, dict):
            kind = "a list (use [i])" if isinstance(node, list) else f"not a mapping ({node!r})"
            raise ScenarioError(f"--set {key}: {here} is {kind}")
        if depth == len(parts) - 1:
            node[part] = value
            return
        if isinstance(part, str) and node.get(part) is None:
            node[part] = [] if isinstance(parts[depth + 1], int) else {}
        node = node[part]


def yaml_loader():
    """PyYAML's safe loader that also reads ``1e-6`` as a number (YAML 1.2, as Drake does)."""
    import yaml  # noqa: PLC0415  (PyYAML ships with drake's dependencies)

    class Loader(yaml.SafeLoader):
        pass

    Loader.add_implicit_resolver("tag:yaml.org,2002:float", _NUMBER_WITH_EXPONENT, list("-+0123456789."))
    return Loader


def _leaves(mapping: dict, prefix: str = ""):
    """(dotted path, value) of every non-mapping value in a nested mapping."""
    for key, value in mapping.items():
        path = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, dict) and value:
            yield from _leaves(value, path)
        else:
            yield path, value


def override_pairs(overrides):
    """(key, value) of each override, in order: ``overrides`` is a sequence of ``key=value``
    strings (values are YAML) or one YAML mapping text (``"controller: {K: 40}"``, each leaf a
    key).  A generator, so that a bad pair is reported after the ones before it were applied."""
    import yaml  # noqa: PLC0415

    loader = yaml_loader()
    if isinstance(overrides, str):
        try:
            mapping = yaml.load(overrides, Loader=loader)  # noqa: S506  (a SafeLoader subclass)
        except yaml.YAMLError:
            raise ScenarioError(f"--set: {overrides!r} is not valid YAML") from None
        if not isinstance(mapping, dict):
            raise ScenarioError(f"--set: expected a mapping, got {overrides!r}")
        yield from _leaves(mapping)
        return
    for pair in overrides:
        if "=" not in pair:
            raise ScenarioError(f"--set: expected key=value, got {pair!r}")
        key, raw = (v.strip() for v in pair.split("=", 1))
        try:
            value = yaml.load(raw, Loader=loader)  # noqa: S506
        except yaml.YAMLError:
            raise ScenarioError(f"--set {key}: value {raw!r} is not valid YAML") from None
        yield key, value


def override_text(text: str, overrides) -> str:
    """The scenario YAML ``text`` with ``overrides`` applied (``override_pairs``: ``key=value``
    strings or a YAML mapping).  Keys are paths with dots and list indices
    (``interceptions[0].target.linear.start``); values are YAML.  Field names are not checked
    here: ``parse_scenario`` reports unknown ones with their path.  Without overrides, and
    when ``text`` itself is no YAML mapping (``parse_scenario`` reports it), ``text`` as is."""
    import yaml  # noqa: PLC0415

    if not overrides:
        return text
    try:
        tree = yaml.load(text, Loader=yaml_loader())  # noqa: S506
    except yaml.YAMLError:
        return text
    tree = {} if tree is None else tree
    if not isinstance(tree, dict):
        return text
    applied = 0
    for key, value in override_pairs(overrides):
        set_path(tree, key, value)
        applied += 1
    return yaml.safe_dump(tree, sort_keys=False) if applied else text


def drake_version() -> str:
    """The installed Drake's version (pip's metadata)."""
    from importlib.metadata import PackageNotFoundError, version  # noqa: PLC0415

    try:
        return version("drake")
    except PackageNotFoundError:  # a source build of pydrake
        return "(unknown version)"


def dump_yaml(scenario) -> str:
    """The scenario as YAML text that ``parse_scenario`` reads back to the same scenario.

    Written with Drake's ``yaml_dump_typed``, then made portable across the supported Drake
    versions: a ``simulator`` field that only some of them have (``_VERSION_SPECIFIC_SIMULATOR``)
    is left out while it holds the value that means "absent", so a file written under Drake 1.51
    loads under 1.58 and back.  A non-default value is kept (it matters on this Drake); another
    Drake then rejects it with a message naming the field.  A plugin's ``controller.params`` are
    written as plain YAML.
    """
    import yaml  # noqa: PLC0415

    params = dict(scenario.controller.params)  # Drake's dumper cannot write a list inside a sum type
    scenario = dataclasses.replace(scenario, controller=dataclasses.replace(scenario.controller, params={}))
    data = yaml.safe_load(yaml_dump_typed(scenario))
    data["controller"]["params"] = params
    simulator = data.get("simulator", {})
    for key, absent in _VERSION_SPECIFIC_SIMULATOR.items():
        if key in simulator and simulator[key] == absent:
            del simulator[key]

    class Dumper(yaml.SafeDumper):  # Drake's layout: block mappings, flow lists of numbers
        pass

    Dumper.add_representer(list, lambda d, v: d.represent_sequence(
        "tag:yaml.org,2002:seq", v, flow_style=not any(isinstance(x, (dict, list)) for x in v)))
    return yaml.dump(data, Dumper=Dumper, sort_keys=False, width=100)


def yaml_error(text: str, schema, exc: Exception) -> str:
    """One line for a YAML load failure, naming the field where it can be located."""
    import yaml  # noqa: PLC0415

    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        return f"scenario YAML: malformed{where}: {getattr(err, 'problem', None) or err}"
    found = _locate(raw, schema, "")
    detail = " ".join(str(exc).split())
    return f"{found}" if found else f"scenario YAML: {detail}"


def _locate(raw, schema, path: str) -> Optional[str]:
    """Walk raw YAML data against a dataclass schema; describe the first mismatch."""
    if dataclasses.is_dataclass(schema):
        if not isinstance(raw, dict):
            return f"{path or 'scenario'}: expected a mapping, got {raw!r}"
        hints = typing.get_type_hints(schema)
        for key, value in raw.items():
            where = f"{path}.{key}" if path else str(key)
            if key not in hints:
                return f"{where}: unknown field (known: {', '.join(hints)})"
            found = _locate(value, hints[key], where)
            if found:
                return found
        return None
    origin = typing.get_origin(schema)
    if origin in (typing.Union, types.UnionType):
        inner = [a for a in typing.get_args(schema) if a is not type(None)][0]
        return None if raw is None else _locate(raw, inner, path)
    if origin in (list, List):
        if not isinstance(raw, list):
            return f"{path}: expected a list, got {raw!r}"
        item = typing.get_args(schema)[0]
        for i, v in enumerate(raw):
            found = _locate(v, item, f"{path}[{i}]")
            if found:
                return found
        return None
    if schema is float:
        if isinstance(raw, bool) or not isinstance(raw, (int, float)):
            try:
                float(raw)
            except (TypeError, ValueError):
                return f"{path}: expected a number, got {raw!r}"
    if schema is str and not isinstance(raw, str):
        return f"{path}: expected a string, got {raw!r}"
    if schema in (SimulatorConfig, MultibodyPlantConfig) and not isinstance(raw, dict):
        return f"{path}: expected a mapping, got {raw!r}"
    if schema in (SimulatorConfig, MultibodyPlantConfig):  # the installed Drake's fields
        known = dump_dataclass(schema())
        for key in raw:
            if key not in known:
                hint = (f" (a field of other Drake versions, not of the installed {drake_version()}: "
                        f"delete it)" if key in _VERSION_SPECIFIC_SIMULATOR else "")
                return f"{path}.{key}: unknown field{hint} (known: {', '.join(known)})"
            found = _locate(raw[key], type(known[key]), f"{path}.{key}")  # the default's type
            if found:
                return found
    return None


def dump_dataclass(obj) -> dict:
    """A plain dict of a scenario (Drake's SimulatorConfig and MultibodyPlantConfig included, with
    every field the installed Drake has, through Drake's ``yaml_dump_typed``), for reports."""
    if dataclasses.is_dataclass(obj):
        return {f.name: dump_dataclass(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, (SimulatorConfig, MultibodyPlantConfig)):
        import yaml  # noqa: PLC0415

        return yaml.safe_load(yaml_dump_typed(obj))
    if isinstance(obj, list):
        return [dump_dataclass(v) for v in obj]
    return obj
