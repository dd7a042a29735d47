"""The wheel carries every sub-package: pyproject.toml lists packages by hand (setuptools'
``packages``), and a sub-package missing there installs editable but breaks a plain ``pip install``
(CI's fresh clone found ``ptint_drake.systems.perception`` missing)."""

from pathlib import Path

import pytest

tomllib = pytest.importorskip("tomllib")  # Python >= 3.11 (CI's two ends: 3.11 and 3.13)

ROOT = Path(__file__).resolve().parents[2]


def test_every_package_directory_is_listed():
    listed = set(tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "ptint_drake").rglob("__init__.py")
             if "__pycache__" not in p.parts}
    assert found - listed == set(), f"sub-packages missing from pyproject.toml: {sorted(found - listed)}"
    assert "ptint_drake.models" in listed  # models/ installs as ptint_drake.models (package-dir)
