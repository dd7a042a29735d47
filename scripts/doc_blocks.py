"""Every generated block of README.md and docs/: which file, which marker, what writes it.

    .venv/bin/python scripts/doc_blocks.py                 # rewrite every block (runs what they need)
    .venv/bin/python scripts/doc_blocks.py --check         # exit 1 and name each stale block
    .venv/bin/python scripts/doc_blocks.py results picks   # only these blocks

A block sits between ``<!-- BEGIN name -->`` and ``<!-- END name -->``.  Its generator is a
function of its inputs, never of the files it is written into:

* ``runs``: metrics of scenario runs (``runs_of(name)``: (scenario, YAML overrides) pairs).  The
  script simulates them; ``tests/e2e/test_doc_blocks_runs.py`` feeds the generators the suite's
  session-cached runs (``conftest.run_cached``) instead, so a run another test made is not made
  again.
* ``paper``: a comparison ``ptint paper`` makes (compare_NAME/compare.json); the script runs the
  comparison, ``tests/e2e/test_visuals.py`` feeds the one its shared ``ptint paper`` run wrote.
* ``json``: the committed output of a study too long for a test (``docs/_data/NAME.json``,
  written by the study's own script or ``--store-*`` here, with its stamp); the block is the
  rendering of that file and ``tests/unit/test_doc_blocks.py`` checks it is.
* ``tests``: the counts ``pytest --collect-only -q`` reports (checked by the unit test).

``differences(old, new)`` is the comparison the check and the tests use: the text must be equal
except (a) table columns that are timings of the machine (``EXEMPT_COLUMNS``) and stamp lines
(``STAMP``: "measured DATE on MACHINE, Python X, Drake Y, commit Z", and after "; " the timings
measured then), which any other stamp replaces, and (b) numbers, which may differ by
``ABS_TOL + REL_TOL·|x|`` in the printed unit (mm, N·m, s, °): the runs are deterministic on one
Drake, but CI checks the blocks on Drake 1.51.1 and the newest, which integrate the last digits
of a near-zero error differently (0.01 mm is 1 % of the 1 mm criterion; the tutorial notebooks'
tables agree across both to 3 significant digits, tests/e2e/test_notebooks.py).
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import re
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "docs" / "_data"

PAPER = ("curve_b025_tf15", "curve_b050_tf15", "curve_b075_tf15", "curve_b075_tf12", "curve_b075_tf19",
         "assembly")
PICKS = ("conveyor_pick_place", "assembly_pick_place")
POSE_VARIANTS = {"nominal": "", "mass ×0.7": "plant: {mass_scale: 0.7}",
                 "mass ×1.5": "plant: {mass_scale: 1.5}"}
# scenario → (the segment column's title, each segment's label)
POSE_SCENARIOS = {"conveyor_yaw": ("part (yaw)", ("0 (0°)", "1 (30°)", "2 (−45°)")),
                  "curve_pose": ("segment", ("0 (curve, tumbling)",))}

EXEMPT_COLUMNS = ("RTF", "realtime factor")
ABS_TOL, REL_TOL = 0.01, 0.02
# a stamp line, and after "; " the machine's timings measured then
STAMP = re.compile(r"measured \d{4}-\d\d-\d\d on [^,]+, Python [\d.]+, Drake [\d.]+, "
                   r"commit (?:[0-9a-f]{7,}|unknown)(; .*)?")  # unknown: a tree outside git


def paper_hold_overrides(name: str) -> str:
    """The YAML override of the paper's own hold after tf (``k_hold = k``) for scenario ``name``."""
    from ptint_drake.simulation.scenario import load_scenario  # noqa: PLC0415

    return f"controller: {{k_hold: {load_scenario(name).controller.k!r}}}"


def runs_of(block: str) -> list[tuple[str, str]]:
    """The (scenario, overrides) runs a ``runs`` block is generated from."""
    if block == "results":
        return [(n, "") for n in PAPER] + [(n, paper_hold_overrides(n)) for n in PAPER]
    if block == "picks":
        return [(n, "") for n in PICKS]
    if block == "pose":
        return [(n, o) for n in POSE_SCENARIOS for o in POSE_VARIANTS.values()]
    raise KeyError(block)


# -- the stamp of machine-dependent numbers ------------------------------------------------------

def commit() -> str:
    """The short hash of the tree's HEAD ("unknown" outside a git checkout)."""
    done = subprocess.run(["git", "rev-parse", "--short=7", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                          check=False)
    return done.stdout.strip() or "unknown"


def stamp(date: Optional[str] = None) -> str:
    """``measured DATE on N-core ARCH, Python X, Drake Y, commit Z`` for today's machine."""
    from importlib.metadata import version  # noqa: PLC0415

    day = date or datetime.datetime.now(datetime.timezone.utc).date().isoformat()
    return (f"measured {day} on {os.cpu_count()}-core {platform.machine()}, Python "
            f"{platform.python_version()}, Drake {version('drake')}, commit {commit()}")


def mm(v: Optional[float], digits: int = 4) -> str:
    return "–" if v is None else f"{v * 1e3:.{digits}g}"


# -- the generators ------------------------------------------------------------------------------

def results(metrics: dict, paper_holds: dict, when: str) -> str:
    """The paper scenarios (README.md, docs/results.md): ``metrics`` and ``paper_holds`` map each
    of PAPER to its run's metrics (the latter with ``k_hold = k``); ``when``: the stamp."""
    lines = ["| scenario | β | tf [s] | e0 | e(tf/2) | e(tf) | ė(tf) [mm/s] | hold max (k_hold = 50) "
             "| hold max (paper: k_hold = k) | peak τ [N·m] | peak τ after start-up [N·m] | verdict | RTF |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name in PAPER:
        m = metrics[name]
        holds = [s["e_hold_max_norm"] for s in paper_holds[name]["segments"]]
        rtf = f"{m['sim']['realtime_factor']:.1f}"
        for i, seg in enumerate(m["segments"]):
            first = i == 0
            label = name if len(m["segments"]) == 1 else f"{name} #{i + 1}"
            lines.append(
                f"| {label} | {seg['beta']:g} | {seg['tf']:g} | {mm(seg['e0_norm'])} "
                f"| {mm(seg['e_half_norm'])} | {mm(seg['e_tf_norm'], 3)} | {mm(seg['edot_tf_norm'], 3)} "
                f"| {mm(seg['e_hold_max_norm'], 3)} | {mm(holds[i], 3)} "
                f"| {', '.join(f'{v:.2f}' for v in m['torque_peak']) if first else ''} "
                f"| {', '.join(f'{v:.2f}' for v in m['torque_peak_after_startup']) if first else ''} "
                f"| {m['status'] if first else ''} | {rtf if first else ''} |")
    return "\n".join(lines) + (
        "\n\n`ptint run NAME` for each (and `--set controller.k_hold=3` for the paper's hold), written by "
        "`scripts/doc_blocks.py` and checked against the test suite's runs "
        "(`tests/e2e/test_doc_blocks_runs.py`); "
        f"RTF (end-to-end realtime factor) depends on the machine:\n{when}.")


def picks(metrics: dict, when: str) -> str:
    """The pick-and-place table (README.md, docs/pick_place.md): one row per pick of PICKS."""
    lines = ["| scenario | pick | part → slot | t_grasp (prescribed) [s] | placed | place error [mm, °] "
             "| slip [mm] | peak grip [N] | realtime factor |", "|---|---|---|---|---|---|---|---|---|"]
    for name in PICKS:
        m = metrics[name]
        for k, p in enumerate(m["picks"]):
            prescribed = p["t_grasp_prescribed"]
            grasp = "never" if p["t_grasp"] is None else f"{p['t_grasp']:.3f} ({prescribed:.3f})"
            rtf = f"{m['sim']['realtime_factor']:.2f}" if k == 0 else ""
            lines.append(f"| {name if k == 0 else ''} | {k} | {p['part']} → {p['slot']} | {grasp} | "
                         f"{'yes' if p['placed'] else 'NO'} | "
                         f"{p['place_error_mm']:.2f}, {p['place_error_deg']:.2f} "
                         f"| {p['slip_mm']:.2f} | {p['peak_grip_force_N']:.0f} | {rtf} |")
    return "\n".join(lines) + (
        "\n\n`ptint run NAME`, written by `scripts/doc_blocks.py` and checked against the test suite's "
        "runs; the realtime factor (end to end) depends on the machine and its load:\n" + when + ".")


def _pose_cell(seg: dict, distance: str, angle: str) -> str:
    return f"{seg[distance] * 1e3:.3g} mm / {seg[angle]:.3g}°"


def pose(metrics: dict) -> str:
    """docs/pose.md's tables: ``metrics[(scenario, overrides)]`` for POSE_SCENARIOS × POSE_VARIANTS."""
    parts = []
    for name, (title, labels) in POSE_SCENARIOS.items():
        rows = [f"| plant | {title} | e(tf/2) | e(tf) | hold max | verdict |", "|---|---|---|---|---|---|"]
        for variant, overrides in POSE_VARIANTS.items():
            m = metrics[(name, overrides)]
            for seg, label in zip(m["segments"], labels):
                rows.append(f"| {variant} | {label} | {_pose_cell(seg, 'e_half_norm', 'e_rot_half_deg')} | "
                            f"{_pose_cell(seg, 'e_tf_norm', 'e_rot_tf_deg')} | "
                            f"{_pose_cell(seg, 'e_hold_max_norm', 'e_rot_hold_max_deg')} | {m['status']} |")
        parts.append(f"`{name}`:\n\n" + "\n".join(rows))
    return "\n\n".join(parts) + (
        "\n\n`ptint run NAME [--set plant.mass_scale=S]` (distance / angle of the gripper to the part), "
        "written by `scripts/doc_blocks.py` and checked against the test suite's runs.")


def test_counts(collected: dict) -> str:
    """docs/quickstart.md's counts: ``collected`` maps "all", "unit" and "oldest" (the oldest
    Drake end's selection) to pytest's counts."""
    return (f"The suite has {collected['all']} tests, {collected['unit']} of them unit tests; the "
            f"oldest Drake end runs {collected['oldest']}: the unit tests and the "
            f"{collected['oldest'] - collected['unit']} e2e tests marked `both_ends` "
            "(`pytest --collect-only -q -m 'not e2e or both_ends'`; counted by "
            "`scripts/doc_blocks.py`, checked by `tests/unit/test_doc_blocks.py`).")


def collect_counts() -> dict:
    """How many tests pytest collects in the whole suite, in tests/unit, and in the oldest Drake
    end's selection (one collection, the others deselected)."""
    done = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-n", "0",
                           "-m", "not e2e or both_ends", "tests"], cwd=ROOT, capture_output=True, text=True,
                          check=False)
    found = re.search(r"(\d+)/(\d+) tests? collected \((\d+) deselected\)|(\d+) tests? collected",
                      done.stdout)
    if found is None or done.returncode != 0:  # a collection error is not a count
        raise RuntimeError(f"pytest --collect-only: {done.stdout[-500:]}{done.stderr[-500:]}")
    kept, total = (int(found.group(1)), int(found.group(2))) if found.group(1) else (int(found.group(4)),) * 2
    ids = [line for line in done.stdout.splitlines() if "::" in line]
    assert len(ids) == kept, (len(ids), kept)
    return {"all": total, "unit": sum(line.startswith("tests/unit/") for line in ids), "oldest": kept}


def rgbd_picks(data: dict) -> str:
    """docs/camera.md's table of the camera pick gate over seeds (docs/_data/rgbd_picks.json,
    ``scripts/rgbd_pick_table.py``'s output with its stamp)."""
    def spread(s: dict) -> str:
        return " / ".join(f"{s[k]:.2f}" for k in ("median", "p90", "max"))

    lines = ["| scenario | placed | place error mm (median / p90 / max) | place error ° (median / p90 / max) "
             "| estimate mm (median / p90 / max) | estimate ° (median / p90 / max) |",
             "|---|---|---|---|---|---|"]
    for g in data["gates"]:
        lines.append(f"| `{g['scenario']}` | {g['placed']} / {g['parts']} | {spread(g['place_error_mm'])} "
                     f"| {spread(g['place_error_deg'])} | {spread(g['estimate_error_mm'])} "
                     f"| {spread(g['estimate_error_deg'])} |")
    return "\n".join(lines) + (
        f"\n\nThe rendering of `docs/_data/rgbd_picks.json` ({data['source']}) by `scripts/doc_blocks.py`; "
        "too long for a test to re-run, so the test checks this table against that file.")


def speed(data: dict) -> str:
    """docs/speed.md's wall times (docs/_data/speed.json, ``scripts/doc_blocks.py --measure-speed``):
    the machine's, exempt from the comparison but stamped."""
    lines = ["| command | wall time [s] |", "|---|---|"]
    lines += [f"| `{row['command']}` | {row['wall_s']:.1f} |" for row in data["rows"]]
    return "\n".join(lines) + (
        f"\n\nWhole-process wall times ({data['load']}), written from `docs/_data/speed.json` by "
        f"`scripts/doc_blocks.py --measure-speed`:\n{data['stamp']}.")


def robust(data: dict) -> str:
    """docs/pick_place.md's robust studies (docs/_data/pick_robust.json: each study's own
    robust.json with its command, and the stamp; ``--store-robust``)."""
    def counts(d: dict) -> str:
        return ", ".join(f"{k} {v}" for k, v in sorted(d.items(), key=lambda kv: (-kv[1], kv[0]))) or "none"

    lines = ["| ranges | samples ok | `pick_success_rate` | `failures_by_reason` | `collisions_by_body` "
             "| wall time [s] |", "|---|---|---|---|---|---|"]
    for study in data["studies"]:
        r = study["robust"]
        lines.append(f"| {r['ranges_preset']} | {round(r['success_rate'] * r['samples'])} of {r['samples']} "
                     f"| {r['pick_success_rate']:.2f} | {counts(r.get('failures_by_reason', {}))} "
                     f"| {counts(r.get('collisions_by_body', {}))} "
                     f"| {r['wall_time_s']:.0f} ({r['workers']} worker{'s' if r['workers'] > 1 else ''}) |")
    commands = "; ".join(f"`{s['command']}`" for s in data["studies"])
    return "\n".join(lines) + (
        f"\n\n{commands}. The rendering of `docs/_data/pick_robust.json` (the studies' own robust.json) by "
        "`scripts/doc_blocks.py`; the studies are too long for a test, which checks this table against "
        f"that file. Wall times depend on the machine and its load:\n{data['stamp']}.")


def store_robust(folders: list) -> None:
    """docs/_data/pick_robust.json from the output folders of ``ptint robust`` studies (each
    with its robust.json), stamped with this machine and commit."""
    studies = []
    for folder in folders:
        r = json.loads((Path(folder) / "robust.json").read_text())
        ranges = "" if r["ranges_preset"] == "harsh" else f" --ranges {r['ranges_preset']}"
        command = (f"ptint robust {r['scenario']} --samples {r['samples']} --seed {r['seed']}{ranges} "
                   f"--workers {r['workers']}")
        studies.append({"command": command, "robust": r})
    DATA.mkdir(exist_ok=True)
    text = json.dumps({"studies": studies, "stamp": stamp()}, indent=1)
    (DATA / "pick_robust.json").write_text(text + "\n")


# block → (scenario, controllers (None: the registry's), folders with plugins); the first two are
# what ``ptint paper`` compares (its compare_NAME/compare.json feeds tests/e2e/test_visuals.py)
COMPARES = {"compare_curve_b075_tf15": ("curve_b075_tf15", None, ()),
            "compare_assembly": ("assembly", None, ()),
            "compare_plugin": ("curve_b075_tf15", ("ptsmc", "task_space_pd:TaskSpacePD"), ("examples",))}


def compare(result: dict, controllers: Optional[tuple], when: str) -> str:
    """A compare study condensed (docs/controllers.md, own_controller.md): e(tf), t_arrive and the
    verdict per controller, segment and variant; ``result``: compare.json's content."""
    from ptint_drake.studies.compare import table_rows  # noqa: PLC0415

    variants = result["variants"]
    header = " | ".join(f"{v}: e(tf) / t_arrive / verdict" for v in variants)
    lines = ["| controller | seg | " + header + " |", "|---|---|" + "---|" * len(variants)]
    rows = table_rows(result)
    keys = sorted({(r["controller"], r["segment"]) for r in rows},
                  key=lambda k: (result["controllers"].index(k[0]), k[1]))
    for controller, seg in keys:
        cells = []
        for v in variants:
            r = next(x for x in rows if (x["controller"], x["segment"], x["variant"]) == (controller, seg, v))
            arrive = "never" if r["t_arrive"] is None else f"{r['t_arrive']:.2f} s"
            cells.append(f"{mm(r['e_tf_norm'], 3)} mm / {arrive} / {'ok' if r['ok'] else r['reasons']}")
        lines.append(f"| {controller} | {seg} | " + " | ".join(cells) + " |")
    prescribed = ", ".join(f"{s['start'] + s['tf']:g} s" for s in result["segments"])
    option = f" --controllers {','.join(controllers)}" if controllers else ""
    return "\n".join(lines) + (
        f"\n\n`ptint compare {result['scenario']}{option}` (prescribed interception at {prescribed}), "
        "written by `scripts/doc_blocks.py` and checked by the tests against the runs of the same comparison "
        f"(t_arrive: the first time |e| ≤ 1 mm); its wall time depends on the machine:\n{when}; "
        f"{result['wall_time_s']:.0f} s.")


def run_compare_study(block: str, workers: int = 2) -> dict:
    """The comparison of ``COMPARES[block]`` run now (compare.json's content, without curves)."""
    from ptint_drake.simulation.scenario import LoadedScenario, scenario_text  # noqa: PLC0415
    from ptint_drake.studies.compare import DEFAULT_CONTROLLERS, run_compare  # noqa: PLC0415

    name, controllers, folders = COMPARES[block]
    loaded = LoadedScenario.parse(scenario_text(name)[1], name, (), tuple(str(ROOT / f) for f in folders))
    result = run_compare(loaded, list(controllers or DEFAULT_CONTROLLERS), workers=workers)
    return dict(result, rows=[{k: v for k, v in r.items() if k != "curve"} for r in result["rows"]])


def store_compare(block: str) -> None:
    """docs/_data/BLOCK.json: the comparison run now, with the stamp."""
    DATA.mkdir(exist_ok=True)
    text = json.dumps({"result": run_compare_study(block), "stamp": stamp()}, indent=1)
    (DATA / f"{block}.json").write_text(text + "\n")


TUNED = (*PAPER, "conveyor_pair")  # and the heavy 6-joint arm of tests/heavy_arm.py


def store_tune(workers: int = 2) -> None:
    """docs/_data/tune.json: ``ptint tune`` on each of TUNED and the heavy 6-joint arm, each
    result's gains, per-variant e(tf), runs and wall time, with the stamp."""
    import tempfile  # noqa: PLC0415

    from ptint_drake.simulation.scenario import LoadedScenario, scenario_text  # noqa: PLC0415
    from ptint_drake.studies.tune import TuneSettings, run_tune  # noqa: PLC0415

    sys.path.insert(0, str(ROOT / "tests"))
    from heavy_arm import heavy_arm_scenario, heavy_arm_urdf  # noqa: PLC0415

    folder = Path(tempfile.mkdtemp())
    (folder / "heavy6.urdf").write_text(heavy_arm_urdf())
    cases = [(n, scenario_text(n)[1]) for n in TUNED]
    cases.append(("heavy 6-joint arm (tests/heavy_arm.py)", heavy_arm_scenario(folder / "heavy6.urdf")))
    rows = []
    for name, text in cases:
        r = run_tune(LoadedScenario.parse(text, name.split()[0]), TuneSettings(), workers=workers,
                     say=lambda m: None)
        per = (r.get("smallest_working") or {}).get("per_variant", {})
        rows.append({"name": name, "K": None if r["gains"] is None else r["gains"]["K"],
                     "paper_value": r["paper_value"], "reasons": r.get("reasons", []), "runs": r["runs"],
                     "wall_time_s": r["wall_time_s"], "variants": r["variants"],
                     "e_tf_norm": {v: per[v]["e_tf_norm"] for v in per}})
    DATA.mkdir(exist_ok=True)
    text = json.dumps({"rows": rows, "command": f"ptint tune NAME --workers {workers}", "stamp": stamp()},
                      indent=1)
    (DATA / "tune.json").write_text(text + "\n")


def tune(data: dict) -> str:
    """docs/own_arm.md's tuning table (docs/_data/tune.json, ``--store-tune``)."""
    lines = ["| scenario | tuned K (margin 2) | paper's K | e(tf) nominal / ×0.7 / ×1.5 [mm] | runs "
             "| time [s] |", "|---|---|---|---|---|---|"]
    for r in data["rows"]:
        if r["K"] is None:
            lines.append(f"| {r['name']} | none works ({', '.join(r['reasons'])}) | {r['paper_value']:g} | – "
                         f"| {r['runs']} | {r['wall_time_s']:.0f} |")
            continue
        errors = " / ".join(mm(r["e_tf_norm"][v], 3) for v in r["variants"])
        lines.append(f"| {r['name']} | {r['K']:.3g} | {r['paper_value']:g} | {errors} | {r['runs']} "
                     f"| {r['wall_time_s']:.0f} |")
    return "\n".join(lines) + (
        f"\n\n`{data['command']}`; the rendering of `docs/_data/tune.json` by `scripts/doc_blocks.py`, "
        f"which the tests check this table against; the times depend on the machine:\n{data['stamp']}.")


def store_camera(folder: Path) -> None:
    """docs/_data/camera.json: a ``ptint study camera`` output folder's camera_study.json without
    its per-run rows (the summary the table shows), with the stamp."""
    result = json.loads((Path(folder) / "camera_study.json").read_text())
    result.pop("runs", None)
    DATA.mkdir(exist_ok=True)
    text = json.dumps({"result": result, "command": f"ptint study camera --workers {result['workers']}",
                       "stamp": stamp()}, indent=1)
    (DATA / "camera.json").write_text(text + "\n")


def camera(data: dict) -> str:
    """docs/camera.md's camera study (docs/_data/camera.json, ``--store-camera``)."""
    from ptint_drake.studies.camera import markdown  # noqa: PLC0415

    r = data["result"]
    text = "\n".join(f"**{line[2:]}**" if line.startswith("# ") else line
                     for line in markdown(r["table"], r["seeds"], r["scenario"]).splitlines())
    return text + (
        f"\n\n`{data['command']}`; the rendering of `docs/_data/camera.json` (the study's "
        "camera_study.json without its per-run rows) by `scripts/doc_blocks.py`, which the tests check "
        f"this table against; the wall time depends on the machine:\n{data['stamp']}; "
        f"{r['wall_time_s']:.0f} s with {r['workers']} worker{'s' if r['workers'] > 1 else ''}.")


@dataclass(frozen=True)
class Block:
    """A generated block: its marker ``name``, the files that hold it, and its source."""

    name: str
    files: tuple
    source: str  # "runs", "json", "tests" or "paper" (a comparison ``ptint paper`` makes)


BLOCKS = (
    Block("results", ("README.md", "docs/results.md"), "runs"),
    Block("picks", ("README.md", "docs/pick_place.md"), "runs"),
    Block("pose", ("docs/pose.md",), "runs"),
    Block("tests", ("docs/quickstart.md",), "tests"),
    Block("rgbd_picks", ("docs/camera.md",), "json"),
    Block("pick_robust", ("docs/pick_place.md",), "json"),
    Block("speed", ("docs/speed.md",), "json"),
    Block("compare_curve_b075_tf15", ("docs/controllers.md",), "paper"),
    Block("compare_assembly", ("docs/controllers.md",), "paper"),
    Block("compare_plugin", ("docs/own_controller.md",), "json"),
    Block("tune", ("docs/own_arm.md",), "json"),
    Block("camera", ("docs/camera.md",), "json"),
)
BY_NAME = {b.name: b for b in BLOCKS}


def render(name: str, runs: Optional[Callable[[str, str], dict]] = None, when: Optional[str] = None,
           counts: Optional[dict] = None, compared: Optional[dict] = None) -> str:
    """Block ``name``'s text: ``runs(scenario, overrides)`` gives a run's metrics (``runs``
    blocks), ``when`` their stamp (default: this machine, today), ``counts`` pytest's counts,
    ``compared`` a comparison's compare.json (``paper`` blocks; default: run now)."""
    when = when or stamp()
    if name in COMPARES and BY_NAME[name].source == "paper":
        return compare(compared or run_compare_study(name), COMPARES[name][1], when)
    if name == "compare_plugin":
        data = json.loads((DATA / f"{name}.json").read_text())
        return compare(data["result"], COMPARES[name][1], data["stamp"])
    if name == "results":
        return results({n: runs(n, "") for n in PAPER}, {n: runs(n, paper_hold_overrides(n)) for n in PAPER},
                       when)
    if name == "picks":
        return picks({n: runs(n, "") for n in PICKS}, when)
    if name == "pose":
        return pose({key: runs(*key) for key in runs_of("pose")})
    if name == "tests":
        return test_counts(counts or collect_counts())
    generator = {"rgbd_picks": rgbd_picks, "pick_robust": robust, "speed": speed, "tune": tune,
                 "camera": camera}[name]
    return generator(json.loads((DATA / f"{name}.json").read_text()))


# -- reading, comparing and writing the files ----------------------------------------------------

def _pattern(name: str) -> re.Pattern:
    return re.compile(rf"<!-- BEGIN {re.escape(name)} -->\n(.*?)\n?<!-- END {re.escape(name)} -->", re.S)


def current(name: str, file: str) -> str:
    """The text of block ``name`` in ``file`` (relative to the repository)."""
    found = _pattern(name).search((ROOT / file).read_text())
    if found is None:
        raise KeyError(f"no <!-- BEGIN {name} --> … <!-- END {name} --> in {file}")
    return found.group(1)


def write(name: str, text: str) -> None:
    """Put ``text`` into block ``name`` of each of its files."""
    for file in BY_NAME[name].files:
        path = ROOT / file
        path.write_text(_pattern(name).sub(lambda m: f"<!-- BEGIN {name} -->\n{text}\n<!-- END {name} -->",
                                           path.read_text()))


NUMBER = re.compile(r"[−-]?\d+(?:\.\d+)?(?:e[+−-]?\d+)?")


def _exempt(text: str) -> list[str]:
    """``text`` with the cells of EXEMPT_COLUMNS and each stamp line replaced by markers; a stamp
    line must match STAMP (or it is left as it is, and so differs)."""
    out, exempt = [], set()
    for line in text.splitlines():
        if STAMP.fullmatch(line.rstrip(".")):
            out.append("<stamp>")
            continue
        if line.startswith("|"):
            cells = line.strip().strip("|").split("|")
            if any(c.strip() in EXEMPT_COLUMNS for c in cells):
                exempt = {k for k, c in enumerate(cells) if c.strip() in EXEMPT_COLUMNS}
            else:
                cells = ["<machine>" if k in exempt and c.strip() and not set(c.strip()) <= {"-"} else c
                         for k, c in enumerate(cells)]
            line = "|" + "|".join(cells) + "|"
        else:
            exempt = set()
        out.append(line)
    return out


def _number(s: str) -> float:
    return float(s.replace("−", "-"))


def differences(old: str, new: str) -> list[str]:
    """How block text ``old`` differs from ``new`` beyond the stamp, the machine's timings and the
    numeric tolerance (empty: they match)."""
    a, b = _exempt(old), _exempt(new)
    if len(a) != len(b):
        return [f"{len(a)} lines, the generator writes {len(b)}"]
    found = []
    for x, y in zip(a, b):
        if NUMBER.sub("#", x) != NUMBER.sub("#", y):
            found.append(f"- {x}\n+ {y}")
            continue
        for u, v in zip(NUMBER.findall(x), NUMBER.findall(y)):
            if abs(_number(u) - _number(v)) > ABS_TOL + REL_TOL * abs(_number(v)):
                found.append(f"- {x}\n+ {y}\n  ({u} against {v})")
                break
    return found


def run_metrics(name: str, overrides: str) -> dict:
    """A run's metrics (the script's own runs: one simulation each)."""
    from ptint_drake.simulation import simulate  # noqa: PLC0415
    from ptint_drake.simulation.scenario import parse_with_overrides, scenario_text  # noqa: PLC0415

    _, text = scenario_text(name)
    return simulate(parse_with_overrides(text, overrides or "{}", name)).metrics


def measure_speed() -> None:
    """Time the commands of docs/speed.md's block (one each, whole process) into docs/_data/speed.json."""
    import time  # noqa: PLC0415

    rows = []
    for command in ("ptint run curve_b075_tf15", "ptint run conveyor_pick_place", "ptint paper"):
        args = command.split()[1:]
        start = time.perf_counter()
        subprocess.run([sys.executable, "-m", "ptint_drake", *args, "--quiet", "--out",
                        str(ROOT / "out" / "speed_block" / args[-1])], check=True, capture_output=True)
        rows.append({"command": command, "wall_s": time.perf_counter() - start})
    load = os.getloadavg()[0]
    DATA.mkdir(exist_ok=True)
    (DATA / "speed.json").write_text(json.dumps(
        {"rows": rows, "load": f"one run each, load average {load:.1f}", "stamp": stamp()}, indent=1) + "\n")


def main(argv: Optional[list] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blocks", nargs="*", help=f"the blocks (default: all of {', '.join(BY_NAME)})")
    parser.add_argument("--check", action="store_true", help="exit 1 when a block differs from its generator")
    parser.add_argument("--measure-speed", action="store_true", help="first time docs/speed.md's commands")
    parser.add_argument("--store-compare", action="store_true",
                        help="first run the plugin comparison into docs/_data/compare_plugin.json")
    parser.add_argument("--store-tune", action="store_true", help="first run the tuning table's studies")
    parser.add_argument("--store-camera", type=Path, metavar="FOLDER",
                        help="first store a `ptint study camera` output folder as docs/_data/camera.json")
    parser.add_argument("--store-robust", nargs="+", metavar="FOLDER",
                        help="first store these `ptint robust` output folders as docs/_data/pick_robust.json")
    args = parser.parse_args(argv)
    if args.measure_speed:
        measure_speed()
    if args.store_robust:
        store_robust(args.store_robust)
    if args.store_compare:
        store_compare("compare_plugin")
    if args.store_tune:
        store_tune()
    if args.store_camera:
        store_camera(args.store_camera)
    stale = []
    for name in args.blocks or list(BY_NAME):
        text = render(name, runs=run_metrics)
        for file in BY_NAME[name].files:
            found = differences(current(name, file), text)
            if found and args.check:
                stale.append(f"{file}: block {name}\n" + "\n".join(found))
        if not args.check:
            write(name, text)
    print("\n\n".join(stale) or ("every block matches" if args.check else "blocks written"))
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
