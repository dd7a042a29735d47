"""diagrams/ holds the current exports; `ptint diagram` writes .dot and .svg with Graphviz."""

import shutil
from pathlib import Path

import pytest

from ptint_drake.report import write_diagram
from ptint_drake.scenario import load_scenario

DIAGRAMS = Path(__file__).resolve().parent.parent / "diagrams"


@pytest.mark.parametrize("name", ["curve_b075_tf15", "assembly"])
def test_committed_diagrams_are_current(tmp_path, name):
    if shutil.which("dot") is None:
        pytest.fail("graphviz's dot is missing: run scripts/setup.sh")
    dot, svg = write_diagram(load_scenario(name), tmp_path)
    committed = DIAGRAMS / f"{name}.dot"
    assert committed.read_text() == dot.read_text(), (
        f"{committed} is stale: run `.venv/bin/python scripts/export_diagrams.py`")
    assert (DIAGRAMS / f"{name}.svg").is_file()
    text = svg.read_text()
    assert text.lstrip().startswith("<?xml") and "<svg" in text
    # every block of the interceptor appears, wired to the plant
    for block in ("interceptor_tbg", "interceptor_target", "interceptor_kinematics",
                  "interceptor_surface", "interceptor_controller", "plant"):
        assert block in text
