"""scripts/setup.sh's progress: each step announces itself and its time, a heartbeat line keeps
a long step from looking hung, and a failing step ends the script with that step's exit code,
the heartbeat gone.  The steps run against a stand-in Python whose ``venv`` and ``pip`` are slow
(2.5 s) and whose ``pip`` fails, with graphviz and chromium stand-ins on PATH (no apt-get)."""

import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

SETUP = Path(__file__).resolve().parents[2] / "scripts" / "setup.sh"

FAKE_PYTHON = """#!/usr/bin/env bash
# venv and pip take a while, pip then fails with 7; anything else is the real interpreter's
if [ "$1" = -m ] && [ "$2" = venv ]; then sleep 2.5; mkdir -p "$3/bin"; cp "$0" "$3/bin/python"; exit 0; fi
if [ "$1" = -m ] && [ "$2" = pip ]; then sleep 2.5; exit 7; fi
exec {real} "$@"
"""


DEFAULT_SIGINT = ("import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
                  "os.execvp('bash', ['bash', sys.argv[1]])")


def _stand_ins(tmp_path) -> dict:
    """The environment of a run against the stand-ins (see the module's docstring)."""
    bin_dir = tmp_path / "bin"
    bin_dir.mkdir()
    for tool in ("dot", "chromium"):  # "installed": no apt-get
        (bin_dir / tool).write_text("#!/bin/sh\nexit 0\n")
        (bin_dir / tool).chmod(0o755)
    python = tmp_path / "python"
    python.write_text(FAKE_PYTHON.format(real=sys.executable))
    python.chmod(0o755)
    return dict(os.environ, PATH=f"{bin_dir}:{os.environ['PATH']}", PYTHON=str(python),
                VENV=str(tmp_path / "venv"), HEARTBEAT_S="1")


def _running_in_group(pgid: int) -> list:
    """The processes of process group ``pgid`` that are not zombies (/proc).  A zombie is not
    counted: a child the script's stand-ins left unreaped when Ctrl-C killed them is handed to
    PID 1, which reaps it when it gets round to it (lazily in some sandboxes)."""
    running = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:  # ended meanwhile
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":  # state, ppid, pgrp, ...
            running.append((stat.parent.name, fields[0]))
    return running


def _run_setup(env: dict, on_line=None) -> tuple[int, list]:
    """Run setup.sh in a session of its own; (exit code, [(seconds since the start, line)]).
    ``on_line(proc, line)`` sees each line as it comes.  Fails if anything of the script is still
    running (or holding its output open) a moment after it exited, and then ends that group."""
    started = time.monotonic()
    # the script as a terminal starts it: SIGINT at its default.  A runner that starts the suite with
    # SIGINT ignored (a job put in the background by a non-interactive shell) passes that on, and
    # bash cannot trap a signal ignored on entry: the Ctrl-C cases then failed with pip's exit 7
    proc = subprocess.Popen([sys.executable, "-c", DEFAULT_SIGINT, str(SETUP)], stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, env=env, start_new_session=True)
    stamped = []

    def read():
        for line in proc.stdout:
            stamped.append((time.monotonic() - started, line.rstrip("\n")))
            if on_line is not None:
                on_line(proc, line)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        code = proc.wait(timeout=60)
        reader.join(timeout=3.0)
        time.sleep(0.3)
        assert not reader.is_alive(), "a process of the script still holds its output open"
        assert _running_in_group(proc.pid) == [], "a process of the script is still running"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        reader.join(timeout=3.0)
        proc.stdout.close()
    return code, stamped


def _interrupt(proc) -> None:
    """Ctrl-C as a terminal sends it: to the script's whole process group (if still there)."""
    try:
        os.killpg(proc.pid, signal.SIGINT)
    except ProcessLookupError:
        pass


@pytest.mark.skipif(shutil.which("bash") is None or not Path("/proc/self/stat").exists(),
                    reason="no bash or no /proc")
def test_steps_are_timed_the_heartbeat_ticks_and_a_failing_step_fails_the_script(tmp_path):
    code, stamped = _run_setup(_stand_ins(tmp_path))
    lines = [line for _, line in stamped]
    text = "\n".join(lines)
    assert code == 7, text  # pip's own exit code
    assert f"setup: venv: creating {tmp_path / 'venv'} ..." in lines, text
    assert any(re.fullmatch(r"setup: venv: done in [23] s", line) for line in lines), text
    assert any(re.fullmatch(r"setup: venv: still running, [12] s", line) for line in lines), text
    assert any(re.fullmatch(r"setup: pip upgrade: still running, [12] s", line) for line in lines), text
    assert lines[-1].startswith("setup: FAILED: pip upgrade (exit 7 after "), text
    # never silent for more than the heartbeat's period (and a margin for a loaded machine)
    times = [0.0] + [t for t, _ in stamped]
    assert max(b - a for a, b in zip(times, times[1:])) < 3.0, stamped


@pytest.mark.skipif(shutil.which("bash") is None or not Path("/proc/self/stat").exists(),
                    reason="no bash or no /proc")
def test_ctrl_c_during_a_step_exits_130_and_leaves_nothing_running(tmp_path):
    sent = []

    def interrupt(proc, line):
        if line.startswith("setup: venv: still running") and not sent:
            _interrupt(proc)
            sent.append(line)

    code, stamped = _run_setup(_stand_ins(tmp_path), interrupt)
    lines = [line for _, line in stamped]
    assert code == 130, lines
    assert lines[-1].startswith("setup: interrupted during venv (exit 130"), lines


@pytest.mark.skipif(shutil.which("bash") is None or not Path("/proc/self/stat").exists(),
                    reason="no bash or no /proc")
def test_a_second_ctrl_c_does_not_cut_the_clean_up_short(tmp_path):
    """Ctrl-C pressed again while the script stops its heartbeat: still nothing left running."""
    def interrupt(proc, line):
        if line.startswith(("setup: venv: still running", "setup: interrupted")):
            _interrupt(proc)
            time.sleep(0.05)
            _interrupt(proc)

    code, stamped = _run_setup(_stand_ins(tmp_path), interrupt)
    assert code == 130, stamped
