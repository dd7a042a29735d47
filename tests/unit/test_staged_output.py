"""outputs.staged_output: an interruption never leaves a folder half-moved or a stage behind."""

import json
import os
import signal

import pytest

from ptint_drake.outputs import folder as outputs
from ptint_drake.outputs.folder import METRICS, staged_output


class _Interrupted(Exception):
    pass


@pytest.fixture
def sigint_raises():
    """SIGINT raises ``_Interrupted`` here (whatever handler the test runner installed)."""
    def handler(signum, frame):
        raise _Interrupted

    old = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def _stage_three(stage):
    (stage / "a.txt").write_text("a")
    (stage / "sub").mkdir()
    (stage / "sub" / "b.txt").write_text("b")
    (stage / METRICS).write_text(json.dumps({"status": "ok"}))


def test_ctrl_c_during_the_move_in_completes_it_then_interrupts(tmp_path, monkeypatch, sigint_raises):
    out = tmp_path / "out"
    real_replace, calls = os.replace, []

    def replace_and_interrupt(src, dst):
        calls.append(dst)
        if len(calls) == 1:  # Ctrl-C arrives after the first file of three has moved
            os.kill(os.getpid(), signal.SIGINT)
        real_replace(src, dst)

    monkeypatch.setattr(outputs.os, "replace", replace_and_interrupt)
    with pytest.raises(_Interrupted), staged_output(out) as stage:
        _stage_three(stage)
    monkeypatch.undo()
    assert sorted(p.name for p in out.iterdir()) == [outputs.MANIFEST, "a.txt", METRICS, "sub"]
    assert (out / "sub" / "b.txt").read_text() == "b"
    assert json.loads((out / METRICS).read_text()) == {"status": "ok"}


def test_ctrl_c_while_staging_leaves_the_previous_run_and_no_stage(tmp_path, sigint_raises):
    out = tmp_path / "out"
    with staged_output(out) as stage:
        _stage_three(stage)
    before = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    with pytest.raises(_Interrupted), staged_output(out) as stage:
        (stage / "a.txt").write_text("new")
        os.kill(os.getpid(), signal.SIGINT)
    after = {p.relative_to(out): p.read_bytes() for p in out.rglob("*") if p.is_file()}
    assert after == before  # no stage left; the previous run's files untouched


def test_signals_deferred_delivers_after_the_block(sigint_raises):
    done = []
    with pytest.raises(_Interrupted):
        with outputs.signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            done.append("rest of the block")
    assert done == ["rest of the block"]
