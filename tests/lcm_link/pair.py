"""Run a plan of processes (inside the private namespace, ``netns.run_in_netns``) and print
what became of each as JSON: ``python pair.py PLAN_JSON``.

PLAN: a list of {"name", "argv", "delay" (s before starting), "start_when" ([other name, text]:
started once that process's stderr shows the text, after the steps without one), "kill_when"
([other name, text]:
a signal once that process's stderr shows the text, e.g. a progress line), "signal" (its name,
default "SIGKILL"), "timeout" (s)}.
Result: {name: {"rc", "stdout", "stderr", "started", "ended", "killed", "origin"}}, wall times in s
from the plan's start (``origin``: that start on ``time.monotonic``'s clock).
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> None:
    plan = json.loads(sys.argv[1])
    folder = Path(tempfile.mkdtemp(prefix="ptint_pair_"))
    t0 = time.monotonic()
    procs = {}
    for step in sorted(plan, key=lambda s: (s.get("start_when") is not None, s.get("delay", 0.0))):
        while time.monotonic() - t0 < step.get("delay", 0.0):
            time.sleep(0.01)
        when = step.get("start_when")
        while when and when[1] not in (folder / f"{when[0]}.err").read_text():
            if procs[when[0]]["proc"].poll() is not None:
                break  # (it ended without the text: started anyway, the test sees it)
            time.sleep(0.01)
        name = step["name"]
        out, err = open(folder / f"{name}.out", "w"), open(folder / f"{name}.err", "w")
        procs[name] = {
            "step": step,
            "proc": subprocess.Popen(step["argv"], stdout=out, stderr=err),
            "started": time.monotonic() - t0,
            "files": (out, err),
            "killed": None,
        }
    result: dict = {}
    while len(result) < len(procs):
        for name, p in procs.items():
            if name in result:
                continue
            now = time.monotonic() - t0
            proc, step = p["proc"], p["step"]
            if proc.poll() is None:
                when = step.get("kill_when")
                if when and p["killed"] is None and when[1] in (folder / f"{when[0]}.err").read_text():
                    p["killed"] = time.monotonic() - t0  # (the signal's own time, not the loop's)
                    proc.send_signal(getattr(signal, step.get("signal", "SIGKILL")))
                elif now - p["started"] >= step.get("timeout", 120.0):
                    proc.kill()
                continue
            for f in p["files"]:
                f.close()
            result[name] = {
                "rc": proc.returncode,
                "stdout": (folder / f"{name}.out").read_text(),
                "stderr": (folder / f"{name}.err").read_text(),
                "started": p["started"],
                "ended": now,
                "killed": p["killed"],
                "origin": t0,  # time.monotonic() of the plan's start (CLOCK_MONOTONIC: perf_counter's)
            }
        time.sleep(0.005)
    print(json.dumps(result))


if __name__ == "__main__":
    main()
