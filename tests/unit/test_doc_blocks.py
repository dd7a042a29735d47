"""Every generated block of README.md and docs/ is known to scripts/doc_blocks.py; the blocks
made from committed study output (docs/_data/*.json) and the test counts are what their
generators write; the comparison exempts only the machine's timings and stamps, and bites."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import doc_blocks  # noqa: E402

OTHER_TESTS = {"layers (scripts/layers_doc.py)": "tests/unit/test_layers.py",
               "arms": "tests/unit/test_arm_table.py",  # scripts/arm_table.py --check: its gains exactly
               "interop": "tests/unit/test_interop_matrix.py"}  # scripts/interop_matrix.py --check


def _markers() -> set:
    names = set()
    for path in [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]:
        names |= {(m, path.relative_to(ROOT).as_posix())
                  for m in re.findall(r"<!-- BEGIN (.+?) -->", path.read_text())}
    return names


def test_every_block_in_the_docs_has_a_generator_and_every_generator_a_block():
    known = {(b.name, f) for b in doc_blocks.BLOCKS for f in b.files}
    found = _markers()
    assert {m for m in found if m[0] not in OTHER_TESTS} == known


@pytest.mark.parametrize("block", [b for b in doc_blocks.BLOCKS if b.source == "json"], ids=lambda b: b.name)
def test_study_block_is_the_rendering_of_its_committed_json(block):
    text = doc_blocks.render(block.name)
    for file in block.files:
        assert doc_blocks.current(block.name, file) == text, (
            f"{file}'s block {block.name} differs from docs/_data/{block.name}.json "
            f"(python scripts/doc_blocks.py {block.name})")


def test_test_counts_are_what_pytest_collects():
    counts = doc_blocks.collect_counts()
    assert counts["all"] > counts["oldest"] > counts["unit"] > 0
    assert doc_blocks.current("tests", "docs/quickstart.md") == doc_blocks.test_counts(counts)


TABLE = """| scenario | e(tf) | verdict | RTF |
|---|---|---|---|
| curve | 0.0708 | ok | 13.0 |

measured 2026-12-05 on 2-core x86_64, Python 3.13.0, Drake 1.58.0, commit abc1234."""


def test_the_machines_timings_and_stamp_are_exempt():
    other = TABLE.replace("13.0", "4.2").replace("2026-12-05", "2027-01-02").replace("abc1234", "0123456")
    assert doc_blocks.differences(TABLE, other) == []


def test_a_number_beyond_the_tolerance_or_a_word_is_stale():
    assert doc_blocks.differences(TABLE, TABLE.replace("0.0708", "0.0712")) == []  # within 0.01 + 2 %
    assert doc_blocks.differences(TABLE, TABLE.replace("0.0708", "0.0908")) != []
    assert doc_blocks.differences(TABLE, TABLE.replace("| ok |", "| missed |")) != []
    assert doc_blocks.differences(TABLE, TABLE + "\n| extra | 1 | ok | 1 |") != []


def test_a_timing_without_its_stamp_is_stale():
    unstamped = TABLE.replace(", commit abc1234", "")
    assert doc_blocks.differences(unstamped, TABLE) != []
    assert doc_blocks.STAMP.fullmatch(doc_blocks.stamp().rstrip("."))
