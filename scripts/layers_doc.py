"""Write docs/design.md's block of the package's layers from pyproject.toml's import-linter
contracts (the list CI checks): ``python scripts/layers_doc.py`` (``--check``: exit 1 if the
block differs, as tests/unit/test_layers.py does)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[1]
BEGIN, END = "<!-- BEGIN layers (scripts/layers_doc.py) -->", "<!-- END layers -->"


def block() -> str:
    """The Markdown of the layers: one row per layer of each layers contract, top first."""
    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]
    lines = []
    for contract in contracts:
        if contract["type"] != "layers":
            continue
        container = contract["containers"][0]
        lines += [f"**{contract['name']}** (`{container}`, top to bottom):", "", "| layer | modules |",
                  "|---|---|"]
        for k, layer in enumerate(contract["layers"]):
            names = re.split(r"\s*[|:]\s*", layer)
            lines.append(f"| {k + 1} | " + ", ".join(f"`{n}`" for n in names) + " |")
        lines.append("")
    others = [c["name"] for c in contracts if c["type"] != "layers"]
    lines += ["Also checked: " + "; ".join(others) + "."]
    return "\n".join([BEGIN, *lines, END])


def main(argv: list[str]) -> int:
    path = ROOT / "docs" / "design.md"
    text = path.read_text()
    new = re.sub(re.escape(BEGIN) + r".*?" + re.escape(END), lambda _: block(), text, flags=re.S)
    if "--check" in argv:
        return 0 if new == text else 1
    path.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
