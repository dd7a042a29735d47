"""Sphinx configuration of the ptint_drake documentation site.

Build (after ``bash scripts/setup.sh``, which installs the ``docs`` extra)::

    .venv/bin/sphinx-build -W -b html docs docs/_build/html

Warnings are errors; nothing is downloaded at build time (no intersphinx).  The command-line
reference and the scenario schema are generated from the code at every build
(``_ext/ptint_reference.py`` → ``_generated/``), and the tutorial notebooks of ``examples/`` are
copied into ``tutorials/`` and rendered with their committed outputs, not executed.
"""

import logging
import shutil
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE / "_ext"))

import ptint_reference  # noqa: E402

ptint_reference.write_generated(HERE / "_generated")
NOTEBOOKS = ("your_diagram", "camera", "which_controller", "pose", "pick_and_place", "hardware")
(HERE / "tutorials").mkdir(exist_ok=True)
for _name in NOTEBOOKS:
    _source = ROOT / "examples" / f"{_name}.ipynb"
    if _source.exists():
        shutil.copyfile(_source, HERE / "tutorials" / f"{_name}.ipynb")

project = "ptint_drake"
author = "ptint_drake contributors"
copyright = "ptint_drake contributors"
extensions = ["ptint_docstrings", "myst_nb", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
exclude_patterns = ["_build", "_generated", "Thumbs.db", ".DS_Store"]
source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
nb_execution_mode = "off"  # the notebooks carry their outputs (tests/e2e/test_notebooks.py)
myst_heading_anchors = 3
html_theme = "alabaster"
html_static_path = ["_static"]
html_theme_options = {"page_width": "1200px", "sidebar_width": "230px"}
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "show-inheritance": False}
autodoc_typehints = "description"
napoleon_numpy_docstring = False
suppress_warnings = ["mystnb.unknown_mime_type"]


class _NoConfigurationDump(logging.Filter):
    """myst-parser and myst-nb log their whole configuration objects (``MdParserConfig(...)``,
    ``NbParserConfig(...)``, each one line of ~1,500 characters) and the jupyter-cache path at
    the info level of every build, unconditionally; this site sets them here, so the dump says
    nothing a reader of this file does not know.  They are kept at ``-v`` (sphinx-build's
    verbose mode), dropped otherwise; every warning and error passes."""

    def __init__(self, verbose: bool):
        super().__init__()
        self.verbose = verbose

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno > logging.INFO or self.verbose:
            return True
        message = str(record.msg)  # the format string, before its arguments are put in
        return not ("myst v%s:" in message or "myst-nb v%s:" in message
                    or message.startswith("Using jupyter-cache at"))


def setup(app):
    """The filter above on the loggers of myst-parser and myst-nb, before their
    ``builder-inited`` handlers log the configuration."""
    quiet = _NoConfigurationDump(verbose=app.verbosity > 0)
    for name in ("sphinx.myst_parser.sphinx_ext.main", "sphinx.myst_nb.sphinx_ext"):
        logging.getLogger(name).addFilter(quiet)
