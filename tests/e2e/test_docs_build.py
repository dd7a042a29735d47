"""The documentation site builds (Sphinx, warnings as errors) and its log is Sphinx's own
progress only: myst-parser's and myst-nb's configuration dumps are kept for ``-v``
(docs/conf.py)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.mark.slow
@pytest.mark.skipif(importlib.util.find_spec("sphinx") is None, reason="the docs extra is not installed")
def test_the_docs_build_prints_no_configuration_dump(tmp_path):
    out = subprocess.run([sys.executable, "-m", "sphinx", "-W", "-b", "html", str(DOCS),
                          str(tmp_path / "html")], capture_output=True, text=True, timeout=600, cwd=tmp_path)
    log = out.stdout + out.stderr
    assert out.returncode == 0, log[-3000:]
    assert "build succeeded" in log
    for dump in ("MdParserConfig(", "NbParserConfig(", "Using jupyter-cache at"):
        assert dump not in log, dump
    assert "WARNING" not in log and "ERROR" not in log
