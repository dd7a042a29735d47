"""The package's size limits, checked (``.ci/run``, tests/unit/test_size_check.py): no module of
``ptint_drake/`` over ``MAX_MODULE`` lines, no function or method over ``MAX_FUNCTION`` lines
(its ``def`` line to its last, docstring included).  A module or function past the limit is a
room doing two jobs: split it by concern.

    python scripts/size_check.py [ROOT]     # exit 1 and one line per finding, else a summary line
"""

from __future__ import annotations

import ast
import sys
from pathlib import Path

MAX_MODULE = 400
MAX_FUNCTION = 60


def findings(root: Path) -> list[str]:
    """One line per module or function over its limit, under ``root`` (the package folder)."""
    out = []
    for path in sorted(root.rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        lines = len(text.splitlines())
        name = path.relative_to(root.parent)
        if lines > MAX_MODULE:
            out.append(f"{name}: {lines} lines (limit {MAX_MODULE})")
        for node in ast.walk(ast.parse(text, filename=str(path))):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION:
                    out.append(f"{name}:{node.lineno}: {node.name} is {length} lines (limit {MAX_FUNCTION})")
    return out


def main() -> int:
    root = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "ptint_drake"
    found = findings(root)
    for line in found:
        print(f"size: {line}")
    if not found:
        modules = len(list(root.rglob("*.py")))
        print(f"size: {modules} modules, none over {MAX_MODULE} lines, no function over {MAX_FUNCTION}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
