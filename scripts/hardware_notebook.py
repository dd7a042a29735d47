"""The cells of ``examples/hardware.ipynb`` (the controller and the simulated hardware as two
processes over LCM), in the format of ``scripts/make_notebooks.py`` (Markdown strings start with
``md:``), which writes and executes them.
"""

from __future__ import annotations


def hardware(setup: str) -> list:
    """The cells of ``examples/hardware.ipynb``; ``setup`` is the shared first code cell."""
    return [
        "md:# The controller and the arm as two processes (LCM)\n\n"
        "A lab's arm is driven the Drake way: a robot driver publishes the arm's status and takes "
        "torque commands over [LCM](https://lcm-proj.github.io/), in Drake's own messages "
        "(`lcmt_iiwa_status` / `lcmt_iiwa_command` for the joints, `lcmt_schunk_wsg_*` for a "
        "gripper). `ptint hardware SCENARIO` plays that driver with the simulated world; `ptint "
        "drive SCENARIO` is the controller alone. The truth, and so the verdict, stays on the "
        "hardware side, which writes `metrics.json` with a `hardware` block of what the link "
        "measured (docs/hardware.md).\n\n"
        "The two processes below run inside a private network namespace that has only loopback "
        "(`unshare -rn`, the multicast route on `lo`): no packet can leave the machine. Where such "
        "a namespace cannot be made (a container without user namespaces), the same two sides run "
        "as two threads of this kernel over an in-memory LCM (`memq://`, `ptint_drake.hardware."
        "in_memory`): the same messages and checks, the round trip then being the threads' turns "
        "at Python's interpreter lock rather than a process-to-process latency.",
        setup,
        """\
import json
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SETUP_NS = "ip link set lo up && ip route add 224.0.0.0/4 dev lo"


def namespace_problem():
    \"\"\"Why a loopback-only network namespace cannot be made here (None: it can).\"\"\"
    if shutil.which("unshare") is None or shutil.which("ip") is None:
        return "no unshare or ip command"
    probe = subprocess.run(["unshare", "-rn", "sh", "-c", SETUP_NS + " && ip -o link | wc -l"],
                           capture_output=True, text=True)
    if probe.returncode != 0 or probe.stdout.strip() != "1":
        return (probe.stderr.strip() or probe.stdout.strip())[:120]
    return None


problem = namespace_problem()
print("private namespace:", "yes" if problem is None else f"no ({problem}): the in-memory fallback")""",
        "md:The scenario: the paper's curve (β = 0.75), shortened to 1 s with tf = 0.8 s so that the "
        "cell runs in seconds; the hardware steps in **lockstep** (each plant step waits for its "
        "command: the mode the accuracy checks use) at the control period of 1 ms.",
        """\
SCENARIO = "curve_b075_tf15"
SETS = ["duration=1.0", "interceptions[0].tf=0.8"]
out = Path(tempfile.mkdtemp(prefix="ptint_hardware_"))


def ptint(*args):
    return [sys.executable, "-m", "ptint_drake.cli", *args,
            *[a for s in SETS for a in ("--set", s)]]


if problem is None:  # two processes in a private namespace: hardware first, the drive 0.5 s later
    hw = " ".join(ptint("hardware", SCENARIO, "--lockstep", "--quiet", "--out", str(out / "hw")))
    dr = " ".join(ptint("drive", SCENARIO, "--out", str(out / "dr")))
    both = f"{SETUP_NS} && ({hw} & sleep 0.5; {dr}; wait)"
    done = subprocess.run(["unshare", "-rn", "sh", "-c", both], capture_output=True, text=True)
    print(done.stdout.strip())
    metrics = json.loads((out / "hw" / "metrics.json").read_text())
    drive = json.loads((out / "dr" / "drive.json").read_text())
    how = "two processes, private namespace"
else:  # the same two sides as two threads over memq://
    from ptint_drake.hardware.session import LinkSettings
    from ptint_drake.hardware.in_memory import run_pair
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text

    scenario = parse_with_overrides(scenario_text(SCENARIO)[1], SETS, SCENARIO)
    metrics, drive = run_pair(scenario, LinkSettings(period=0.001, duration=1.0), out / "hw")
    how = "two threads, memq://"
link = metrics["hardware"]
print(how, "| URL", link["url"], "| mode", link["mode"], "| ticks", link["ticks"])""",
        "md:The verdict and the error at tf come from the hardware side (the true object); in "
        "lockstep they do not depend on the machine's speed, and equal `ptint run "
        "curve_b075_tf15 --set controller.control_period=0.001 --set multibody.time_step=0.001` "
        "(measured: within 10⁻¹⁰ m):",
        """\
seg = metrics["segments"][0]
print(f"verdict {metrics['status']}: e(tf) = {seg['e_tf_norm'] * 1e3:.4f} mm, "
      f"hold max = {seg['e_hold_max_norm'] * 1e3:.4f} mm")""",
        "md:What the link measured — these numbers are the machine's (its load, its scheduler), so "
        "they change from run to run: the round trip (status handed to LCM → its command handled "
        "by the hardware), the period achieved between two ticks, the messages re-sent and "
        "missing, and the drive's own compute time per command.",
        """\
def row(name, spread, unit="ms"):
    if spread is None:
        return f"| {name} | — | — | — |"
    cells = [f"{spread[k]:.3f} {unit}" for k in ("median", "p99", "max")]
    return f"| {name} | " + " | ".join(cells) + " |"


lines = ["| | median | p99 | max |", "|---|---|---|---|",
         row("round trip", link["round_trip_ms"]), row("period achieved", link["achieved_period_ms"]),
         row("drive compute", drive["compute_ms"])]
print("\\n".join(lines))
print(f"statuses sent {link['statuses_sent']}, re-sent {link['status_resends']}, dropped "
      f"{link['statuses_dropped']}; commands accepted {link['commands_accepted']}; ticks missing at "
      f"the drive {drive['ticks_missing']}; second-sender check: {link['sender_check']}")""",
        "md:The pick world (`conveyor_pick_place`) runs the same way, with the gripper's status and "
        "command (`lcmt_schunk_wsg_status` / `lcmt_schunk_wsg_command`) and the part tracker's "
        "reports (`lcmt_scope` on `TRACKED_POSES`) beside the arm's messages; the targets, the gripper's "
        "sequence and the grasp observer run in the drive. Faults (a dead drive, a NaN command, a "
        "second sender) hold the arm: docs/hardware.md has each one's measured reaction.",
    ]
