"""scripts/compare_versions.py: a bad --python is one line, not a traceback."""

import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "compare_versions.py"


def test_a_missing_python_is_one_line_naming_the_option(tmp_path):
    out = subprocess.run([sys.executable, str(SCRIPT), "--python", "venv/bin/python"],
                         capture_output=True, text=True, cwd=tmp_path, timeout=60)
    assert out.returncode == 1
    assert out.stderr.strip() == f"compare_versions: --python {tmp_path}/venv/bin/python: no such executable"
    assert out.stdout == ""
