"""Benchmark the bundled scenarios; prints JSON: the command ``ptint bench`` (its options:
``ptint bench --help``; ``ptint_drake/studies/benchmark.py`` does the work).

    .venv/bin/python scripts/benchmark.py [SCENARIO ...] [--configs default,blocks,sign] [--no-reference]
"""

import sys

from ptint_drake.cli import main

if __name__ == "__main__":
    sys.exit(main(["bench", *sys.argv[1:]]))
