"""scripts/size_check.py: the package within its limits, and the check finds what is over them."""

from __future__ import annotations

from pathlib import Path

from script_module import load_script

ROOT = Path(__file__).resolve().parents[2]


def _size_check():
    return load_script("size_check")


def test_the_package_is_within_its_limits():
    assert _size_check().findings(ROOT / "ptint_drake") == []


def test_a_long_module_and_a_long_function_are_found(tmp_path):
    check = _size_check()
    package = tmp_path / "pkg"
    package.mkdir()
    body = "\n".join(f"    x{i} = {i}" for i in range(check.MAX_FUNCTION))
    (package / "long.py").write_text(f"def long():\n{body}\n" + "\n" * check.MAX_MODULE)
    found = check.findings(package)
    assert len(found) == 2 and "long is 61 lines" in found[1] and "lines (limit 400)" in found[0]
