"""The tables of the documentation page on intercepting a pose (docs/pose.md, issue 19):
``conveyor_yaw`` and ``curve_pose`` on the nominal plant and with every link's mass × 0.7 and
× 1.5 — distance and angle at tf/2, at tf and the hold's largest, per segment.

    .venv/bin/python scripts/pose_table.py      # the six runs; the same as scripts/doc_blocks.py pose

The block ``pose`` of docs/pose.md is written by ``scripts/doc_blocks.py`` (its generator and
its runs are there; tests/e2e/test_doc_blocks_runs.py checks it against the suite's runs).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from doc_blocks import main  # noqa: E402

if __name__ == "__main__":
    sys.exit(main(["pose", *sys.argv[1:]]))
