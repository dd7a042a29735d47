"""A study's forkserver imports the package its caller imports, not a ``ptint_drake`` folder in
the caller's working folder (``studies.workers.start_forkserver``): CPython starts the server with
the working folder first on its path, so inside a source tree with a non-editable install the
server imported the tree, and numba compiled every kernel again there."""

import json
import subprocess
import sys

from conftest import IMPORTED_FROM

# run in a folder holding a decoy ptint_drake; this package put first on the path explicitly
CALLER = """
import json, os, sys, threading
sys.path.insert(0, {root!r})
import ptint_drake
from ptint_drake.studies.runner import run_tasks
stop = threading.Event()
threading.Thread(target=stop.wait, daemon=True).start()  # a second thread: no fork, a forkserver
stats = {{}}
names = ["PYTHONSAFEPATH", "_PTINT_FORKSERVER_SAFE_PATH"]
in_workers = run_tasks(os.getenv, [(name,) for name in names], workers=2, stats=stats)
stop.set()
print(json.dumps({{"method": stats["start_method"], "in_workers": in_workers, "here": ptint_drake.__file__,
                  "here_after": [os.getenv(name) for name in names]}}))
"""


def test_the_forkserver_does_not_import_a_ptint_drake_in_the_working_folder(tmp_path):
    decoy = tmp_path / "ptint_drake"
    decoy.mkdir()
    marker = tmp_path / "decoy_imported"
    (decoy / "__init__.py").write_text(f"open({str(marker)!r}, 'a').write('imported')\n")
    done = subprocess.run([sys.executable, "-c", CALLER.format(root=str(IMPORTED_FROM))], cwd=tmp_path,
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    out = json.loads(done.stdout.splitlines()[-1])
    assert out["method"] == "forkserver" and not out["here"].startswith(str(tmp_path))
    # the server's PYTHONSAFEPATH is neither left in the caller nor in the workers
    assert out["in_workers"] == [None, None] and out["here_after"] == [None, None]
    assert not marker.exists(), "the forkserver imported the working folder's ptint_drake"
