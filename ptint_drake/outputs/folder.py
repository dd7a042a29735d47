"""Writing a run's files into an output folder without ever leaving it half-written.

Everything is written into a hidden temporary folder beside the final files
and moved in with ``os.replace`` only when complete; ``metrics.json`` is moved
last, and the previous run's ``metrics.json`` is removed first, so a folder
whose ``metrics.json`` exists always holds one complete run.  An interrupted
run leaves the folder as it was, minus the old ``metrics.json``.

Ctrl-C (SIGINT) and SIGTERM are held while the staged files move in and while the
temporary folder is removed (``signals_deferred``): an interruption then takes effect
right after, so it neither leaves a move half-done nor the temporary folder behind.  A
process that ends without unwinding (a worker stopped by SIGTERM) first removes the folders
it is staging (``remove_live_stages``).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path

import numpy as np

METRICS = "metrics.json"
SERIES = "series.npz"


def current_umask() -> int:
    """The process's umask (``os.umask`` can only be read by setting it; set it back at once)."""
    try:  # Linux ≥ 4.7 shows it without changing it
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _as_if_created(path, mode: int) -> None:
    """Give a file from ``mkstemp`` (0600) or a folder from ``mkdtemp`` (0700) the mode an
    ordinary ``open``/``mkdir`` would have: ``mode`` (0666 / 0777) minus the umask."""
    os.chmod(path, mode & ~current_umask())


def write_text_atomic(path: Path, text: str) -> None:
    """Write ``text`` (UTF-8) to ``path`` through a temporary file beside it and
    ``os.replace``: ``path`` is either the old file or the whole new one, and an interruption
    leaves no temporary file.  The file gets the usual mode for the user's umask (0644 under
    umask 022)."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        _as_if_created(tmp, 0o666)
        with os.fdopen(fd, "w", encoding="utf-8", newline="") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json_atomic(path: Path, data) -> None:
    """Write ``data`` as JSON (indented, a final newline) to ``path`` (``write_text_atomic``)."""
    write_text_atomic(path, json.dumps(data, indent=2) + "\n")


MANIFEST = ".ptint-manifest.json"
_HELD = (signal.SIGINT, signal.SIGTERM)
_LIVE_STAGES: dict = {}  # stage folder → pid of the process that staged it (forks inherit this)


def remove_live_stages() -> None:
    """Delete the folders this process is staging (``staged_output``): for a process about to
    end without unwinding, e.g. a worker stopped by SIGTERM (``studies.runner``).  Those a
    forked child inherited from its parent stay: they are the parent's."""
    pid = os.getpid()
    for stage, owner in list(_LIVE_STAGES.items()):
        if owner == pid:
            shutil.rmtree(stage, ignore_errors=True)
            del _LIVE_STAGES[stage]


@contextmanager
def signals_deferred():
    """Hold SIGINT and SIGTERM until the block ends: their Python handlers are swapped for one
    that only notes the signal, and the first one noted is handed to its own handler after
    the block (e.g. ``KeyboardInterrupt`` raised right after it).  A signal the process
    ignores stays ignored.  Only the main thread can set handlers: elsewhere a no-op.
    (Masking with ``pthread_sigmask`` would not do: the kernel hands a process's signal to
    any thread that does not mask it, e.g. one of OpenBLAS's.)"""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    previous = {}
    for signum in _HELD:
        handler = signal.getsignal(signum)
        if handler not in (signal.SIG_IGN, None):
            previous[signum] = signal.signal(signum, lambda n, _frame: noted.append(n))
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if noted:
            handler = previous[noted[0]]
            if callable(handler):
                handler(noted[0], None)
            else:  # SIG_DFL: the signal's default action (SIGTERM ends the process)
                signal.raise_signal(noted[0])


@contextmanager
def staged_output(out_dir: Path, additive: bool = False):
    """Yield a temporary folder; on success its files replace those in ``out_dir``.

    ``metrics.json`` (if staged) is moved last.  Files that the previous run in
    ``out_dir`` wrote (listed in its manifest) and this one did not are removed,
    so two runs never mix.  ``additive`` outputs (files named after what they show,
    e.g. one diagram per scenario) only add or replace their own files and leave the
    folder's other files and its manifest alone.  On any failure (or Ctrl-C) the
    temporary folder is deleted and ``out_dir`` keeps no new file.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    stage = None
    try:
        with signals_deferred():
            stage = Path(tempfile.mkdtemp(prefix=".ptint-stage-", dir=out_dir))
            _LIVE_STAGES[stage] = os.getpid()
        _as_if_created(stage, 0o777)
        yield stage
        with signals_deferred():
            _move_in(stage, out_dir, additive)
    finally:
        if stage is not None:
            with signals_deferred():
                shutil.rmtree(stage, ignore_errors=True)
                _LIVE_STAGES.pop(stage, None)


def _move_in(stage: Path, out_dir: Path, additive: bool) -> None:
    """``staged_output``'s commit: the staged files replace those in ``out_dir``,
    ``metrics.json`` last; then the previous run's other files go (unless ``additive``)."""
    (out_dir / METRICS).unlink(missing_ok=True)
    names = sorted((p.name for p in stage.iterdir()), key=lambda n: n == METRICS)
    for name in names:
        target = out_dir / name
        if target.is_dir():
            shutil.rmtree(target)
        os.replace(stage / name, target)
    if additive:
        return
    try:
        previous = set(json.loads((out_dir / MANIFEST).read_text()))
    except (OSError, ValueError):
        previous = set()
    for name in previous - set(names):
        stale = out_dir / name
        if stale.is_dir():
            shutil.rmtree(stale, ignore_errors=True)
        elif "/" not in name and stale.exists():
            stale.unlink()
    write_json_atomic(out_dir / MANIFEST, names)


def save_series(path: Path, series: dict) -> None:
    """The logged time series (t, q, v, tau, x, x_r, e, edot, xi, alpha, s_x, ...) as .npz."""
    np.savez_compressed(path, **series)
