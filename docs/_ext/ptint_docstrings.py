"""A Sphinx extension: the package's docstrings, written as plain text, rendered faithfully.

The docstrings are plain text with reStructuredText's inline literals (````name````): norms
written ``|e(tf)|``, equations and port tables indented under a paragraph, Markdown tables.
Read as reStructuredText those are substitutions and unexpected indentation; this hook
(``autodoc-process-docstring``, before napoleon) turns every indented block, every Markdown
table and every simple table into a literal block and escapes the remaining ``|`` and ``*``,
so that the text shows as written and the build (warnings as errors) passes.
"""

from __future__ import annotations

import re

_SECTION = re.compile(
    r"^\s*(Args|Arguments|Parameters|Returns|Raises|Yields|Attributes|Examples?|Notes?):\s*$")


def _indent(line: str) -> int:
    return len(line) - len(line.lstrip())


def _is_rule(line: str) -> bool:
    return line.strip().startswith("==") and set(line.strip()) <= {"=", " "}


def _escape(line: str) -> str:
    """``|`` and ``*`` outside inline literals made literal characters."""
    parts = re.split(r"(``.+?``)", line)
    return "".join(p if p.startswith("``") and p.endswith("``") and len(p) > 4
                   else p.replace("\\", "\\\\").replace("|", "\\|").replace("*", "\\*")
                   for p in parts)


def plain_to_rst(lines: list) -> list:
    """The docstring ``lines`` (dedented by autodoc) as reStructuredText; see the module doc."""
    out, i, base = [], 0, 0
    while i < len(lines):
        line = lines[i]
        if not line.strip():
            out.append(line)
            i += 1
            continue
        if _is_rule(line):  # a reStructuredText simple table: up to its third rule, as written
            rules, start = 0, i
            while i < len(lines) and rules < 3:
                rules += _is_rule(lines[i])
                i += 1
            if out and out[-1].strip():
                out.append("")
            out += [" " * base + "::", ""] + ["    " + b for b in lines[start:i]] + [""]
            continue
        table = line.lstrip().startswith("|")
        indented = _indent(line) > base and out and not _SECTION.match(out[-1] if out[-1].strip() else "")
        prev_literal = bool(out) and out[-1].rstrip().endswith("::")
        if table or indented or prev_literal:
            block = []
            ind = _indent(line)
            while i < len(lines) and (not lines[i].strip() or _indent(lines[i]) >= ind
                                      or (table and lines[i].lstrip().startswith("|"))):
                if not lines[i].strip() and (i + 1 >= len(lines) or
                                             (_indent(lines[i + 1]) < ind and not table)):
                    break
                if table and lines[i].strip() and not lines[i].lstrip().startswith("|"):
                    break
                block.append(lines[i])
                i += 1
            if not prev_literal:
                if out and out[-1].strip():
                    out.append("")
                out += [" " * base + "::", ""]
            elif out[-1].strip():
                out.append("")
            out += ["    " + b[min(ind, _indent(b)):] if b.strip() else "" for b in block]
            out.append("")
            continue
        base = _indent(line)
        if line.rstrip().endswith("::"):
            out.append(_escape(line.rstrip()[:-2]) + "::")
        else:
            out.append(_escape(line))
        i += 1
    return out


def _process(app, what, name, obj, options, lines):  # noqa: ARG001  (Sphinx's signature)
    lines[:] = plain_to_rst(list(lines))


def setup(app):
    """Register the hook before napoleon's (priority 400 < 500), after loading autodoc."""
    app.setup_extension("sphinx.ext.autodoc")
    app.connect("autodoc-process-docstring", _process, priority=400)
    return {"parallel_read_safe": True, "version": "1"}
