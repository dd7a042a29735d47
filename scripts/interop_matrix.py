"""The interop matrix of docs/hardware.md (issue 45: Drake's drivers, both directions): every
sender × receiver × mode × status period case run as real processes in lockstep, and the table
of what each gave written between ``<!-- BEGIN interop -->`` and ``<!-- END interop -->``.

The cases, for the iiwa (``curve_iiwa14``, ``lcmt_iiwa_*``) and the Panda (``curve_panda``,
``--messages panda``: ``lcmt_panda_*``):

- ``ptint drive`` → ``ptint hardware --lockstep`` (torque);
- ``ptint drive`` → the station of Drake's blocks (``scripts/drake_blocks_station.py``) in each
  driver mode the drive takes off, the mismatched pairs (a term left in), at 1 ms and at 5 ms;
- Drake's command sender (``scripts/drake_command_sender.py``, a hold of the start pose) →
  ``ptint hardware --lockstep``, torque-only and position + torque;
- a second ``ptint drive`` started mid-run → ``ptint hardware --lockstep`` (``curve_b075_tf15``).

Each process pair runs inside a private network namespace with loopback alone (``unshare -n``,
or ``-rn`` when not root; the script re-runs itself there), one pair at a time::

    python scripts/interop_matrix.py                 # every case (~6 min), writes the block
    python scripts/interop_matrix.py --only panda    # the cases whose name holds "panda"; prints
    python scripts/interop_matrix.py --check         # exit 1 if the block lacks a case's row

``--only`` prints the rows without writing the page.  A reference row per arm is ``ptint run`` at
the same 1 ms period and plant step.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shlex
import subprocess
import sys
import time
from importlib.metadata import version
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PAGE = ROOT / "docs" / "hardware.md"
BEGIN, END = "<!-- BEGIN interop -->", "<!-- END interop -->"
SETUP = "ip link set lo up && ip route add 224.0.0.0/4 dev lo"
UNSHARE = ["unshare", "-n"] if os.geteuid() == 0 else ["unshare", "-rn"]
CURVES = {"iiwa": "curve_iiwa14", "panda": "curve_panda"}
PATIENT = ("--startup-timeout", "60")
SENDER_SET = ("--set", "duration=2.0")  # the command sender's hold: 2 s
GRACE = 10.0  # s the others may run on once the receiver has ended (a drive waiting for a status)


def cases() -> list[dict]:
    """Every case: its name, arm (message set), sender, receiver, mode and status period."""
    out = []
    for arm in CURVES:
        out.append({"name": f"{arm}-hardware", "arm": arm, "kind": "hardware", "mode": "torque",
                    "period": 0.001})
        for station, drive, period in [("torque_only", "torque-gravity", 0.001),
                                       ("position_and_torque", "position-torque", 0.001),
                                       ("torque_only", "torque", 0.001),
                                       ("position_and_torque", "torque-gravity", 0.001),
                                       ("torque_only", "torque-gravity", 0.005),
                                       ("position_and_torque", "position-torque", 0.005)]:
            out.append({"name": f"{arm}-station-{station}-{drive}-{period * 1e3:g}ms", "arm": arm,
                        "kind": "station", "mode": (drive, station), "period": period})
        for mode in ("torque_only", "position_and_torque"):
            out.append({"name": f"{arm}-sender-{mode}", "arm": arm, "kind": "sender", "mode": mode,
                        "period": 0.001})
    out.append({"name": "iiwa-second-drive", "arm": "iiwa", "kind": "second", "mode": "torque",
                "period": 0.001})
    return out


def ptint(*args: str) -> list[str]:
    return [sys.executable, "-m", "ptint_drake", *args]


def script(name: str, *args: str) -> list[str]:
    return [sys.executable, str(ROOT / "scripts" / name), *args]


def run_pair(first: list[str], second: list[str], out: Path, start_when: str | None = None,
             third: list[str] | None = None, timeout: float = 300.0) -> dict:
    """``first`` and ``second`` (and ``third`` once ``first``'s stderr shows ``start_when``) as
    processes; {name: (rc, stderr)}."""
    out.mkdir(parents=True, exist_ok=True)
    procs, logs = {}, {}
    for name, argv in (("first", first), ("second", second)):
        logs[name] = out / f"{name}.err"
        procs[name] = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=open(logs[name], "w"))
    start = time.monotonic()
    ended = None  # when the first process (the receiver) ended: the others get GRACE s more
    while any(p.poll() is None for p in procs.values()) and time.monotonic() - start < timeout:
        if ended is None and procs["first"].poll() is not None:
            ended = time.monotonic()
        if ended is not None and time.monotonic() - ended > GRACE:
            break
        if third and "third" not in procs and start_when in logs["first"].read_text():
            logs["third"] = out / "third.err"
            procs["third"] = subprocess.Popen(third, stdout=subprocess.DEVNULL,
                                              stderr=open(logs["third"], "w"))
        time.sleep(0.05)
    for p in procs.values():
        if p.poll() is None:
            p.kill()
            p.wait()
    return {name: (p.returncode, logs[name].read_text()) for name, p in procs.items()}


def errors(seg: dict) -> str:
    return f"e(tf) {seg['e_tf_norm'] * 1e3:.4f} mm, hold max {seg['e_hold_max_norm'] * 1e3:.4f} mm"


def station_case(case: dict, out: Path) -> str:
    """ptint drive → Drake's blocks: the station's verdict and errors, or how it ended."""
    drive_mode, station_mode = case["mode"]
    curve, over = CURVES[case["arm"]], ("--messages", case["arm"])
    period = f"{case['period']:g}"
    got = run_pair(script("drake_blocks_station.py", curve, *over, "--mode", station_mode, "--status-period",
                          period, "--command-timeout", "5", "--out", str(out / "st")),
                   ptint("drive", curve, *over, *PATIENT, "--status-timeout", "5", "--driver-mode",
                         drive_mode, "--out", str(out / "dr")), out)
    failure = [ln for ln in got["first"][1].splitlines() if "condition" in ln or "Failure" in ln]
    if failure:  # Drake's receiver stopped the station (an abort)
        said = re.sub(r"^.*? in (\w+\(\)): ", r"\1: ", failure[0].strip())
        return f"refused by Drake's receiver: the station aborts (`{said[:110]}`)"
    station = json.loads((out / "st" / "station.json").read_text())
    seg = station["segments"][0]
    if station["status"] == "ok":
        return f"ok: {errors(seg)}"
    if station["fault"] is None:
        return f"runs to its end; missed: {errors(seg)}"
    return f"failed: {station['fault']}"


def hardware_case(case: dict, out: Path) -> str:
    """ptint drive → ptint hardware --lockstep over the arm's messages."""
    curve, over = CURVES[case["arm"]], ("--messages", case["arm"])
    run_pair(ptint("hardware", curve, *over, *PATIENT, "--lockstep", "--quiet", "--out", str(out / "hw")),
             ptint("drive", curve, *over, *PATIENT, "--out", str(out / "dr")), out)
    metrics = json.loads((out / "hw" / "metrics.json").read_text())
    return f"{metrics['status']}: {errors(metrics['segments'][0])}"


def sender_case(case: dict, out: Path) -> str:
    """Drake's command sender (a hold) → ptint hardware --lockstep."""
    curve, over = CURVES[case["arm"]], ("--messages", case["arm"])
    got = run_pair(ptint("hardware", curve, *over, *PATIENT, *SENDER_SET, "--lockstep", "--quiet",
                         "--out", str(out / "hw")),
                   script("drake_command_sender.py", curve, *over, "--mode", case["mode"], *SENDER_SET), out)
    link = json.loads((out / "hw" / "metrics.json").read_text())["hardware"]
    if link["fault"] is None:
        return (f"{link['ticks']} ticks, {link['commands_accepted']} commands applied, no fault (a hold: "
                f"the verdict is missed)")
    line = next((ln for ln in got["first"][1].splitlines() if ln.startswith("ptint: error:")), link["fault"])
    said = re.sub(r"^ptint: error: hardware: command rejected at t = [\d.]+ s: ", "", line)
    return f"refused in one line at t = {link['fault_time']:.3f} s: `{said.split(': ptint hardware')[0]}`"


def second_case(case: dict, out: Path) -> str:
    """A second ptint drive started at 10 % → ptint hardware --lockstep: how it was named."""
    longer = ("--set", "duration=20.0")
    got = run_pair(ptint("hardware", "curve_b075_tf15", *PATIENT, *longer, "--lockstep",
                         "--out", str(out / "hw")),
                   ptint("drive", "curve_b075_tf15", *PATIENT, *longer, "--out", str(out / "d1")), out,
                   start_when=" 10 %",
                   third=ptint("drive", "curve_b075_tf15", *PATIENT, *longer, "--out", str(out / "d2")))
    link = json.loads((out / "hw" / "metrics.json").read_text())["hardware"]
    if link["fault_kind"] == "second sender" and link["sender_check"] == "source address":
        return f"named by its source address at t = {link['fault_time']:.3f} s, the arm held"
    return f"not named by its address: {link['fault_kind']} ({got['first'][0]})"


def reference(arm: str, out: Path) -> str:
    """``ptint run`` of the arm's curve at the link's 1 ms period and plant step."""
    subprocess.run(ptint("run", CURVES[arm], "--set", "controller.control_period=0.001", "--set",
                         "multibody.time_step=0.001", "--no-replay", "--no-figures", "--quiet",
                         "--out", str(out)), capture_output=True, check=False)
    metrics = json.loads((out / "metrics.json").read_text())
    return f"{metrics['status']}: {errors(metrics['segments'][0])}"


RUNNERS = {"station": station_case, "hardware": hardware_case, "sender": sender_case, "second": second_case}
SENDERS = {"iiwa": "IiwaCommandSender", "panda": "PandaCommandSender"}
LEFT_IN = {("torque", "torque_only"): " (gravity compensation left in: a feed-forward)",
           ("torque-gravity", "position_and_torque"): " (Coriolis left in)"}


def row(case: dict, result: str) -> str:
    """The case's table row."""
    arm, kind, period = case["arm"], case["kind"], case["period"]
    hw = "`ptint hardware --lockstep`"
    if kind == "station":
        drive, station = case["mode"]
        who = "`ptint drive` → Drake blocks station"
        mode = f"`{drive}` / `{station}`{LEFT_IN.get(case['mode'], '')}"
    elif kind == "hardware":
        who, mode = f"`ptint drive` → {hw}", "`torque`"
    elif kind == "sender":
        who, mode = f"Drake `{SENDERS[arm]}` (a hold of the start pose) → {hw}", f"`{case['mode']}`"
    else:
        who, mode = f"a second `ptint drive` started mid-run → {hw}", "`torque`"
        arm = "rvm1 (curve_b075_tf15)"
    label = f"{period * 1e3:g} ms" + (" (Drake's)" if period == 0.005 else "")
    return f"| {arm} | {who} | {mode} | {label} | {result} |"


def block(rows: list[str]) -> str:
    head = ["| arm (messages) | sender → receiver | mode (drive / station) | status period | result |",
            "|---|---|---|---|---|"]
    note = (f"`python scripts/interop_matrix.py` on {platform.machine()}, Python "
            f"{platform.python_version()}, Drake {version('drake')}, in a private network namespace, "
            f"lockstep; iiwa: curve_iiwa14 over `lcmt_iiwa_*`, panda: curve_panda over `lcmt_panda_*` "
            f"(`--messages panda`).")
    return "\n".join([BEGIN, *head, *rows, "", note, END])


def current_block() -> str:
    match = re.search(re.escape(BEGIN) + ".*?" + re.escape(END), PAGE.read_text(), re.S)
    return match.group(0) if match else ""


def check() -> int:
    """0 when the page's block has a row for every case (by its arm, who and mode)."""
    have = current_block()
    missing = [c["name"] for c in cases() if row(c, "").rsplit("|", 2)[0] not in have]
    if not have or missing:
        print(f"{PAGE.name}: the interop block lacks {', '.join(missing) or 'everything'}: "
              f"run scripts/interop_matrix.py")
        return 1
    return 0


def measure(only: str | None, out: Path) -> list[str]:
    """Run the cases (inside the namespace); their rows, the references first."""
    rows = []
    for arm in CURVES:
        if only is None or only in arm:
            result = reference(arm, out / f"{arm}-reference")
            rows.append(f"| {arm} | `ptint run` (one process: the reference) | — | 1 ms | {result} |")
            print(rows[-1], flush=True)
    for case in cases():
        if only is None or only in case["name"]:
            rows.append(row(case, RUNNERS[case["kind"]](case, out / case["name"])))
            print(rows[-1], flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", help="run the cases whose name holds this (prints, writes nothing)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "interop_matrix")
    parser.add_argument("--check", action="store_true", help="compare the page's block, run nothing")
    args = parser.parse_args(argv)
    if args.check:
        return check()
    if os.environ.get("PTINT_INTEROP_INSIDE") != "1":  # into a private namespace, loopback alone
        env = dict(os.environ, PTINT_INTEROP_INSIDE="1")
        given = sys.argv[1:] if argv is None else argv
        inner = " ".join(shlex.quote(a) for a in [sys.executable, str(Path(__file__).resolve()), *given])
        done = subprocess.run([*UNSHARE, "sh", "-c", f"{SETUP} && exec {inner}"], env=env, check=False)
        return done.returncode
    rows = measure(args.only, args.out)
    if args.only is None:
        text, new = PAGE.read_text(), block(rows)
        PAGE.write_text(text.replace(current_block(), new) if current_block() else text + "\n" + new + "\n")
        print(f"wrote the interop block of {PAGE}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
