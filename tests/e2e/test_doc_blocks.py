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


@pytest.mark.parametrize("block", RUN_BLOCKS, ids=lambda b: b.name)
def test_block_is_what_its_generator_writes_from_the_suites_runs(block):
    text = doc_blocks.render(block.name, runs=_metrics)
    for file in block.files:
        found = doc_blocks.differences(doc_blocks.current(block.name, file), text)
        assert not found, (f"{file}'s block {block.name} is stale (python scripts/doc_blocks.py "
                           f"{block.name}):\n" + "\n".join(found))
