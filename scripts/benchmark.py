"""Benchmark the bundled scenarios; prints JSON (see ptint_drake/benchmark.py).

    .venv/bin/python scripts/benchmark.py [SCENARIO ...] [--configs default,blocks,sign] [--no-reference]
"""

import sys

from ptint_drake.studies.benchmark import main

if __name__ == "__main__":
    sys.exit(main())
