"""``python -m ptint_drake.cli`` is the ``ptint`` command (as ``python -m ptint_drake``)."""

import sys

from ptint_drake.cli import console

sys.exit(console())
