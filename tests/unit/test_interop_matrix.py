"""Issue 45: docs/hardware.md's interop block is scripts/interop_matrix.py's (a row for every
sender × receiver × mode × status period case, the Panda's among them), and its check can fail."""

import subprocess
import sys
from pathlib import Path

from script_module import load_script

ROOT = Path(__file__).resolve().parents[2]


def test_the_page_block_has_a_row_per_case():
    out = subprocess.run([sys.executable, str(ROOT / "scripts" / "interop_matrix.py"), "--check"],
                         capture_output=True, text=True, cwd=ROOT)
    assert out.returncode == 0, out.stdout + out.stderr


def test_each_case_its_own_row_and_the_check_fails_without_one(tmp_path, capsys):
    script = load_script("interop_matrix")
    labels = [script.row(c, "").rsplit("|", 2)[0] for c in script.cases()]
    assert len(set(labels)) == len(labels) == 19  # (the check tells every case from the others)
    assert sum("PandaCommandSender" in x or x.startswith("| panda |") for x in labels) == 9
    text = script.PAGE.read_text()
    script.PAGE = tmp_path / "hardware.md"
    gone = next(line for line in text.splitlines()
                if line.startswith("| panda | `ptint drive` → Drake blocks") and "5 ms" in line
                and "position-torque" in line)
    script.PAGE.write_text(text.replace(gone + "\n", ""))
    assert script.check() == 1
    assert "panda-station-position_and_torque-position-torque-5ms" in capsys.readouterr().out
    script.PAGE.write_text(text)
    assert script.check() == 0
