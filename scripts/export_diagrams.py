"""Regenerate diagrams/: the built Drake diagrams of a curve scenario and of the assembly task,
as they run (NAME.dot/.svg, the fused interceptor) and with the five wired blocks
(NAME_blocks.dot/.svg, controller.implementation = blocks).

    .venv/bin/python scripts/export_diagrams.py

tests/test_diagrams.py fails when the committed .dot files no longer match a fresh export.
"""

import shutil
import tempfile
from pathlib import Path

from ptint_drake.report.run_outputs import write_diagram
from ptint_drake.simulation.scenario import load_scenario, parse_with_overrides, scenario_text

DIAGRAM_SCENARIOS = ("curve_b075_tf15", "assembly")
OUT = Path(__file__).resolve().parent.parent / "diagrams"

def diagram_scenarios(name):
    """The scenario as bundled, and its blocks variant named NAME_blocks."""
    blocks = parse_with_overrides(scenario_text(name)[1], "controller: {implementation: blocks}", name)
    blocks.name = f"{name}_blocks"
    return [load_scenario(name), blocks]


if __name__ == "__main__":
    # each export goes through its own folder: write_diagram's staged output replaces the files
    # that the previous export into the same folder wrote (its manifest), so only copy them in
    for name in DIAGRAM_SCENARIOS:
        for scenario in diagram_scenarios(name):
            with tempfile.TemporaryDirectory() as tmp:
                for path in write_diagram(scenario, Path(tmp)):
                    shutil.copyfile(path, OUT / path.name)
                    print(f"wrote {OUT / path.name}")
