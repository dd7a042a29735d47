"""Files the scripts of ``scripts/`` generate (the arm and gripper models), written or checked."""

from __future__ import annotations

from pathlib import Path


def write_or_check(files: dict[Path, str], check: bool, source: str) -> int:
    """Write each file's text, or with ``check`` compare it with what is on disk and name every
    file that differs from its generator ``source``; the exit code (1: a file differs)."""
    status = 0
    for path, text in files.items():
        if check:
            if not path.is_file() or path.read_text() != text:
                print(f"{path.name}: differs from {source}")
                status = 1
        else:
            path.write_text(text)
            print(f"wrote {path}")
    return status
