"""``python -m ptint_drake.cli.warm_up``'s one option (``scripts/setup.sh``'s WARM_UP_WORKERS)."""

import subprocess
import sys

import pytest

from ptint_drake.cli import warm_up


@pytest.mark.parametrize("value", ["3", "0", "two"])
def test_a_bad_worker_count_is_one_line_naming_the_option_exit_2(value):
    done = subprocess.run([sys.executable, "-m", "ptint_drake.cli.warm_up", "--workers", value],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 2
    assert "--workers" in done.stderr.strip().splitlines()[-1]


def test_one_worker_compiles_every_share_in_this_process_in_turn(monkeypatch, capsys):
    seen, asked = [], []
    monkeypatch.setattr(warm_up, "_compile", lambda share, duration: seen.append(share) or ["done"])
    real = warm_up.warm_up
    monkeypatch.setattr(warm_up, "warm_up", lambda **kw: asked.append(kw["workers"]) or real(**kw))
    warm_up.main(["--workers", "1"])
    assert asked == [1] and seen == list(warm_up._RUNS)
    assert "in one process" in capsys.readouterr().err
