"""Issue 45: docs/own_arm.md's per-arm block is scripts/arm_table.py's, and its check can fail."""

import subprocess
import sys
from pathlib import Path

from script_module import load_script

ROOT = Path(__file__).resolve().parents[2]


def _script():
    return load_script("arm_table")


def test_the_page_block_is_current():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "arm_table.py"), "--check"],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout + out.stderr


def test_check_fails_on_a_changed_gain_or_a_missing_row(tmp_path, capsys):
    script = _script()
    text = script.PAGE.read_text()
    script.PAGE = tmp_path / "own_arm.md"
    script.PAGE.write_text(text.replace("| curve_panda | 41.38 |", "| curve_panda | 40 |"))
    assert script.check() == 1 and "gains differ" in capsys.readouterr().out
    script.PAGE.write_text(text.replace("| ur5e | 0.", "| ur5e | n/a "))
    assert script.check() == 1 and "ur5e" in capsys.readouterr().out
    script.PAGE.write_text(text)
    assert script.check() == 0
