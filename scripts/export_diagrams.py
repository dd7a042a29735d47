"""Regenerate diagrams/: the built Drake diagrams of a curve scenario and of the assembly task.

    .venv/bin/python scripts/export_diagrams.py

tests/test_diagrams.py fails when the committed .dot files no longer match a fresh export.
"""

from pathlib import Path

from ptint_drake.report import write_diagram
from ptint_drake.scenario import load_scenario

DIAGRAM_SCENARIOS = ("curve_b075_tf15", "assembly")
OUT = Path(__file__).resolve().parent.parent / "diagrams"

if __name__ == "__main__":
    for name in DIAGRAM_SCENARIOS:
        for path in write_diagram(load_scenario(name), OUT):
            print(f"wrote {path}")
