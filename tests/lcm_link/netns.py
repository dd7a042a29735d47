"""Run commands inside a private network namespace that has only loopback (SPEC §7: LCM
multicast stays on this machine; no packet can reach the host's own network).

``namespace_problem()`` says why such a namespace cannot be made here (None: it can);
``run_in_netns(argv)`` runs ``argv`` inside a fresh one (``lo`` up, the multicast route
``224.0.0.0/4 dev lo``): ``unshare -n`` as root, so that the processes keep root's real
capabilities (the link's loops ask for SCHED_FIFO, ``hardware.priority``); otherwise
``unshare -rn``, a user namespace beside the network one, whose root cannot change scheduling.
Tests that need two processes call ``require_netns()``, which does not skip silently: without
a namespace it warns with the reason and skips, and the single-process in-memory tests (``memq://``,
tests/unit/test_lcm_checks.py) still run the same checks.
"""

from __future__ import annotations

import functools
import os
import shutil
import subprocess
import warnings

import pytest

SETUP = "ip link set lo up && ip route add 224.0.0.0/4 dev lo"
UNSHARE = ["unshare", "-n"] if os.geteuid() == 0 else ["unshare", "-rn"]


@functools.lru_cache(maxsize=None)
def namespace_problem() -> str | None:
    """Why a loopback-only network namespace cannot be made here (None: it can)."""
    for tool in ("unshare", "ip"):
        if shutil.which(tool) is None:
            return f"no {tool!r} command"
    probe = subprocess.run(
        [*UNSHARE, "sh", "-c", SETUP + " && ip -o link | wc -l"],
        capture_output=True,
        text=True,
        timeout=20,
    )
    if probe.returncode != 0:
        return f"{' '.join(UNSHARE)} failed: {' '.join(probe.stderr.split())[:200]}"
    if probe.stdout.strip() != "1":
        return f"the namespace has {probe.stdout.strip()} links, not loopback alone"
    return None


def require_netns() -> None:
    """Skip, loudly (a warning with the reason), when no private namespace can be made."""
    problem = namespace_problem()
    if problem is not None:
        message = (
            f"LCM two-process test not run: no private network namespace ({problem}); the "
            f"single-process memq:// tests cover the link's checks"
        )
        warnings.warn(message, stacklevel=2)
        pytest.skip(message)


def run_in_netns(argv: list[str], timeout: float, **kwargs) -> subprocess.CompletedProcess:
    """``argv`` inside a fresh loopback-only network namespace (``SETUP``)."""
    return subprocess.run(
        [*UNSHARE, "sh", "-c", SETUP + ' && exec "$@"', "sh", *argv],
        capture_output=True,
        text=True,
        timeout=timeout,
        **kwargs,
    )
