"""The blocks of README.md and docs/ written from scenario runs (scripts/doc_blocks.py: results,
picks, pose) are what their generators write from this suite's own runs: ``run_cached`` shares
each run with the tests that made it (test_curves, test_assembly, test_pick_place, test_pose),
so only the paper-hold runs (``k_hold = k``) and curve_pose's mass variants are new here."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest
from conftest import run_cached

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import doc_blocks  # noqa: E402

RUN_BLOCKS = [b for b in doc_blocks.BLOCKS if b.source == "runs"]


def _metrics(name: str, overrides: str) -> dict:
    return run_cached(name, overrides).metrics


@pytest.mark.slow
@pytest.mark.parametrize("block", RUN_BLOCKS, ids=lambda b: b.name)
def test_block_is_what_its_generator_writes_from_the_suites_runs(block):
    text = doc_blocks.render(block.name, runs=_metrics)
    for file in block.files:
        found = doc_blocks.differences(doc_blocks.current(block.name, file), text)
        assert not found, (f"{file}'s block {block.name} is stale (python scripts/doc_blocks.py "
                           f"{block.name}):\n" + "\n".join(found))


@pytest.mark.both_ends
def test_the_own_diagram_page_snippet_runs_and_meets_the_object_at_tf():
    """docs/own_diagram.md's first code block, executed as it stands, then simulated to tf from
    the pose the page names: the tool within 1 mm of the object."""
    import re

    import numpy as np
    from pydrake.all import Simulator

    code = re.search(r"```python\n(.*?)```", (ROOT / "docs" / "own_diagram.md").read_text(), re.S).group(1)
    space: dict = {}
    exec(compile(code, "own_diagram.md", "exec"), space)  # noqa: S102
    plant, diagram = space["plant"], space["diagram"]
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    plant.SetPositions(plant.GetMyMutableContextFromRoot(context), np.radians([22.5, 45.0, 30.0]))
    simulator.AdvanceTo(1.0)
    tool = plant.CalcPointsPositions(plant.GetMyContextFromRoot(context), plant.GetFrameByName("tool"),
                                     np.zeros(3), plant.world_frame()).ravel()
    target = np.array([0.30, -0.15, 0.15]) + np.array([0.0, 0.1, 0.0]) * 1.0
    assert np.linalg.norm(tool - target) <= 1e-3
