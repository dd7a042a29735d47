"""The house's layers hold: import-linter's contracts in pyproject.toml (layers, the world seam,
only the registry imports the worlds, no cycles inside a layer), and every top-level module and
sub-package of ptint_drake is in the layers contract."""

from __future__ import annotations

import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import tomllib

ROOT = Path(__file__).resolve().parents[2]


def _contracts() -> list:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]["contracts"]


def test_every_top_level_module_is_in_a_layer():
    layers = next(c for c in _contracts() if c.get("containers") == ["ptint_drake"])["layers"]
    named = {name.strip() for layer in layers for part in layer.split("|") for name in part.split(":")}
    # the source tree's (an installed package also holds ``models``, the data folder models/)
    modules = {info.name for info in pkgutil.iter_modules([str(ROOT / "ptint_drake")])}
    assert modules - named == set(), "modules in no layer"
    assert named - modules == set(), "layers naming no module"


def test_lint_imports_keeps_every_contract():
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    assert exe is not None, "import-linter is not installed (pip install -e '.[test]')"
    done = subprocess.run([exe], cwd=ROOT, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stdout[-3000:]
    assert "0 broken" in done.stdout or "broken" not in done.stdout.split("Contracts:")[-1]


def test_a_world_import_outside_the_registry_breaks_a_contract(tmp_path):
    """The contract bites: a study that imports the pick world directly is reported."""
    tree = tmp_path / "ptint_drake"
    shutil.copytree(ROOT / "ptint_drake", tree, ignore=shutil.ignore_patterns("__pycache__", "*.nb*"))
    sweep = tree / "studies" / "sweep.py"
    sweep.write_text(sweep.read_text() + "\nfrom ptint_drake.worlds.pick import tasks  # noqa: E402,F401\n")
    (tmp_path / "pyproject.toml").write_text((ROOT / "pyproject.toml").read_text())
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent))
    done = subprocess.run([exe], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                          env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"})
    assert done.returncode != 0
    assert "Only the world registry imports the worlds BROKEN" in done.stdout


def test_design_md_draws_the_same_layers():
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "layers_doc.py"), "--check"], cwd=ROOT,
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, "docs/design.md's layers differ: run scripts/layers_doc.py"


def test_the_hardware_path_names_no_world():
    """Issue 43: no line of ``ptint_drake/hardware/`` or ``cli/hardware.py`` names a world; what
    a world adds to the link comes from its protocol (``World.link_ports``, ``own_plant_step``,
    ``controller_side``, ``report``)."""
    import re  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    root = Path(__file__).resolve().parents[2] / "ptint_drake"
    files = sorted((root / "hardware").glob("*.py")) + [root / "cli" / "hardware.py"]
    named = [f"{f.name}:{i}: {line.strip()}" for f in files
             for i, line in enumerate(f.read_text().splitlines(), 1)
             if re.search(r"\bpick|\binterception", line, re.IGNORECASE)]
    assert named == []


def test_one_module_constructs_the_simulator():
    """Issue 43: ``Simulator(`` appears in one module (``worlds.base.new_simulator``); every run,
    study, floor and the drive start there."""
    import re  # noqa: PLC0415
    from pathlib import Path  # noqa: PLC0415

    root = Path(__file__).resolve().parents[2] / "ptint_drake"
    found = sorted({str(f.relative_to(root)) for f in root.rglob("*.py")
                    if re.search(r"(?<![_\w])Simulator\(", f.read_text())})
    assert found == ["worlds/base.py"]
