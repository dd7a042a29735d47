"""Scenario YAML in and out: portable dumps, and one-line messages that name the field.

``dump_yaml`` writes a scenario with Drake's ``yaml_dump_typed`` so that
``scenario.parse_scenario`` reads it back to the same scenario, under any supported
Drake; ``yaml_error`` turns a failed ``yaml_load_typed`` into one line naming the
first field that does not fit the schema.
"""

import dataclasses
import types
import typing
from typing import List, Optional

from pydrake.common.yaml import yaml_dump_typed
from pydrake.systems.analysis import SimulatorConfig


# SimulatorConfig fields that only some supported Drake versions have, each with the value that
# means the same as leaving it out (Drake 1.52 removed publish_every_time_step; false was the default).
_VERSION_SPECIFIC_SIMULATOR = {"publish_every_time_step": False}


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
    if schema is SimulatorConfig and not isinstance(raw, dict):
        return f"{path}: expected a mapping, got {raw!r}"
    if schema is SimulatorConfig:  # the installed Drake's fields
        known = dump_dataclass(SimulatorConfig()).keys()
        for key in raw:
            if key not in known:
                hint = (f" (a field of other Drake versions, not of the installed {drake_version()}: "
                        f"delete it)" if key in _VERSION_SPECIFIC_SIMULATOR else "")
                return f"{path}.{key}: unknown field{hint} (known: {', '.join(known)})"
    return None


def dump_dataclass(obj) -> dict:
    """A plain dict of a scenario (SimulatorConfig included, with every field the installed
    Drake has, through Drake's ``yaml_dump_typed``), for reports."""
    if dataclasses.is_dataclass(obj):
        return {f.name: dump_dataclass(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, SimulatorConfig):
        import yaml  # noqa: PLC0415

        return yaml.safe_load(yaml_dump_typed(obj))
    if isinstance(obj, list):
        return [dump_dataclass(v) for v in obj]
    return obj
