"""Issue 45, offline by construction: nothing the package ships needs Drake's remote
``drake_models`` package, checked without trusting the machine's network or its download cache.

Drake keeps what it downloads in ``$TEST_TMPDIR/.cache/drake`` when ``TEST_TMPDIR`` is set, else
in ``$XDG_CACHE_HOME/drake`` when that folder exists, else in ``$HOME/.cache/drake``
(``drake::internal::FindOrCreateCache``).  The build runs in a subprocess without ``TEST_TMPDIR``,
with ``HOME`` and ``XDG_CACHE_HOME`` two fresh folders: nothing downloaded before can help.  A
model that used ``drake_models`` would then fail to parse with no network, or, with a network,
leave the package in the fresh cache — the test finds either.  A canary package fetched from a
local file last shows that the fresh cache is where Drake downloads under that environment.
``DRAKE_ALLOW_NETWORK`` is no guard here (on Drake 1.51.1 its ``none`` makes every ``Parser``
fail, as the default ``PackageMap`` registers the remote ``drake_models``): it is removed from
the subprocess's environment.  The subprocess runs in a private network namespace with loopback
alone where one can be made (``tests/lcm_link/netns.py``): no packet can leave even then.
"""

import os
import subprocess
import sys
import tarfile
from pathlib import Path

from conftest import IMPORTED_FROM
from lcm_link.netns import namespace_problem, run_in_netns
from ptint_drake.simulation.scenario import bundled_scenarios

ROOT = Path(__file__).resolve().parents[2]
NEEDLE = "package://" + "drake_models"  # written in two pieces: this file does not match itself
SKIPPED_FOLDERS = {".git", ".venv", ".venv-oldest", "_build", "node_modules", "__pycache__", "out"}


def _tree_files() -> list[Path]:
    """The checkout's files that git tracks or would (not ignored), else every file outside build and
    environment folders."""
    listed = subprocess.run(["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"], cwd=ROOT,
                            capture_output=True, check=False)
    if listed.returncode == 0 and listed.stdout:
        return [ROOT / name for name in listed.stdout.decode().split("\0") if name]
    return [p for p in ROOT.rglob("*") if p.is_file()
            and not SKIPPED_FOLDERS.intersection(p.relative_to(ROOT).parts)]


def test_no_file_of_the_tree_refers_to_drake_models():
    files = [p for p in _tree_files() if p.is_file()]
    assert any(p.suffix == ".urdf" for p in files) and any(p.suffix == ".yaml" for p in files)
    hits = [str(p.relative_to(ROOT)) for p in files if NEEDLE.encode() in p.read_bytes()]
    assert hits == []


def _canary(folder: Path) -> Path:
    """A .tar.gz holding ``canary/package.xml`` (a package Drake's ``PackageMap`` accepts)."""
    package = folder / "src" / "canary"
    package.mkdir(parents=True)
    (package / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="2"><name>canary</name><version>0.0.0</version>'
        '<description>offline test</description><maintainer email="none@example.com">none</maintainer>'
        "<license>none</license></package>\n")
    archive = folder / "canary.tar.gz"
    with tarfile.open(archive, "w:gz") as tar:
        tar.add(package, arcname="canary")
    return archive


def test_every_bundled_model_and_scenario_builds_with_an_empty_download_cache(tmp_path):
    """Every bundled arm and gripper parses, and every bundled scenario's diagram is built (not
    run), in a subprocess whose download cache is a fresh folder; afterwards Drake's cache holds
    the canary alone (nothing was fetched for the models) and ``HOME`` holds no Drake cache."""
    models = sorted(str(p) for p in (ROOT / "models").iterdir() if p.suffix in (".urdf", ".sdf"))
    assert len(models) >= 8
    home, cache = tmp_path / "home", tmp_path / "cache"
    home.mkdir()
    cache.mkdir()  # Drake takes XDG_CACHE_HOME only when the folder exists
    env = {k: v for k, v in os.environ.items() if k not in ("TEST_TMPDIR", "DRAKE_ALLOW_NETWORK")}
    env |= {"HOME": str(home), "XDG_CACHE_HOME": str(cache),
            "PYTHONPATH": os.pathsep.join([str(IMPORTED_FROM), os.environ.get("PYTHONPATH", "")])}
    argv = [sys.executable, str(ROOT / "tests" / "offline_build.py"), str(_canary(tmp_path)), *models]
    if namespace_problem() is None:  # no packet can leave, even if a model came to need drake_models
        result = run_in_netns(argv, timeout=600, env=env)
    else:  # the fresh cache still shows a download
        result = subprocess.run(argv, capture_output=True, text=True, env=env, check=False, timeout=600)
    assert result.returncode == 0, result.stderr[-2000:]
    lines = result.stdout.splitlines()
    built = sorted(line.split()[1] for line in lines if line.startswith("model "))
    assert built == [Path(m).name for m in models]
    assert [line.split()[1] for line in lines if line.startswith("scenario ")] == bundled_scenarios()
    (canary_line,) = [line for line in lines if line.startswith("canary ")]
    package_map = cache / "drake" / "package_map"
    canary_path = Path(canary_line.split(maxsplit=1)[1])
    assert canary_path.parent == package_map.resolve() and (canary_path / "package.xml").is_file()
    # the canary's folder and its README: nothing else was downloaded
    fetched = sorted(p.name for p in package_map.iterdir())
    assert fetched == sorted([canary_path.name, canary_path.name + ".README"]), fetched
    assert not (home / ".cache" / "drake").exists()
