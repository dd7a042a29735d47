"""README.md's "In your own diagram" example runs as printed: the fenced Python block is taken
from the README, run in a fresh interpreter from a neutral folder, and what it prints is the
interception it promises (the tool within 1 mm of the moving object at tf)."""

import re
import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[2] / "README.md"


def readme_example() -> str:
    """The one ```python block of README.md's "## In your own diagram" section."""
    text = README.read_text()
    section = text.split("## In your own diagram", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```python\n(.*?)```", section, flags=re.S)
    assert len(blocks) == 1, "the section has one Python block"
    return blocks[0]


def test_the_example_is_short():
    code = readme_example()
    assert len(code.splitlines()) <= 15
    assert "AddPrescribedTimeInterceptor(" in code


def test_the_example_runs_and_intercepts(tmp_path):
    script = tmp_path / "example.py"
    script.write_text(readme_example())
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    match = re.fullmatch(r"\|e\(tf\)\| = (\d+\.\d{3}) mm\n", out.stdout)
    assert match, out.stdout
    assert float(match.group(1)) < 1.0  # docs/results.md's criterion at tf


def test_own_diagram_page_names_every_field_of_the_handles():
    """docs/own_diagram.md counts and names ``InterceptorHandles``' fields as the dataclass has them."""
    import dataclasses

    from ptint_drake.controllers.ptsmc.builder import InterceptorHandles

    page = (README.parent / "docs" / "own_diagram.md").read_text()
    paragraph = page.split("`handles` (an `InterceptorHandles`) has ", 1)[1].split("\n\n", 1)[0]
    words = {5: "five", 6: "six", 7: "seven", 8: "eight", 9: "nine", 10: "ten", 11: "eleven"}
    names = [f.name for f in dataclasses.fields(InterceptorHandles)]
    assert paragraph.startswith(f"{words[len(names)]} fields"), paragraph[:40]
    assert all(f"`{name}`" in paragraph for name in names), names
    assert "For your own arm, load\nits URDF instead" in page
