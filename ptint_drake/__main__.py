"""``python -m ptint_drake`` is the ``ptint`` command."""

import sys

from ptint_drake.cli import console

sys.exit(console())
