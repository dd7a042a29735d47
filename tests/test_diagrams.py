"""diagrams/ holds the current exports; `ptint diagram` writes .dot and .svg with Graphviz."""

import importlib.util
import shutil
from pathlib import Path

import pytest

from ptint_drake.report import write_diagram

ROOT = Path(__file__).resolve().parent.parent
DIAGRAMS = ROOT / "diagrams"
_spec = importlib.util.spec_from_file_location("export_diagrams", ROOT / "scripts" / "export_diagrams.py")
export = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(export)


@pytest.mark.parametrize("name", ["curve_b075_tf15", "assembly"])
def test_committed_diagrams_are_current(tmp_path, name):
    if shutil.which("dot") is None:
        pytest.fail("graphviz's dot is missing: run scripts/setup.sh")
    fused, blocks = export.diagram_scenarios(name)
    for scenario, systems in ((fused, ("interceptor", "saturation", "plant")),
                              (blocks, ("interceptor_tbg", "interceptor_target", "interceptor_kinematics",
                                        "interceptor_surface", "interceptor_controller", "plant"))):
        dot, svg = write_diagram(scenario, tmp_path)
        committed = DIAGRAMS / dot.name
        assert committed.is_file() and committed.read_text() == dot.read_text(), (
            f"{committed} is stale: run `.venv/bin/python scripts/export_diagrams.py`")
        assert (DIAGRAMS / svg.name).is_file()
        text = svg.read_text()
        assert text.lstrip().startswith("<?xml") and "<svg" in text
        for system in systems:  # every block appears, wired to the plant
            assert system in text
