"""What ``ptint run`` and ``ptint diagram`` write: a run's folder and a diagram export.

``run_and_write`` simulates, and stages every file (series.npz, figures,
replay.html, metrics.json last) through ``outputs.staged_output``.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np

from ptint_drake.figures import run_figures
from ptint_drake.outputs import METRICS, SERIES, save_series, staged_output, write_json_atomic
from ptint_drake.replay import write_replay
from ptint_drake.robot import resolve_model
from ptint_drake.scenario import Scenario, ScenarioError, dump_dataclass
from ptint_drake.simulation import build, simulate


def conveyor_belts(scenario: Scenario):
    """Belts to draw for linear targets: the stretch each object travels, ±0.1 m."""
    belts = []
    for ic in scenario.interceptions:
        lin = ic.target.linear
        if lin is None:
            continue
        a = np.asarray(lin.start)
        b = a + np.asarray(lin.velocity) * scenario.duration
        d = (b - a) / (np.linalg.norm(b - a) or 1.0)
        belts.append((a - 0.1 * d, b + 0.1 * d))
    return belts


def run_and_write(scenario: Scenario, out_dir: Path, replay: bool = True, figures: bool = True,
                  progress=None, warn=None) -> dict:
    """Simulate ``scenario`` and write its outputs into ``out_dir``; returns the metrics.
    ``warn(message)`` gets the warnings known before the simulation, before it starts."""
    result = simulate(scenario, progress=progress, warn=warn)
    metrics = dict(result.metrics)
    metrics["scenario_config"] = dump_dataclass(scenario)
    with staged_output(out_dir) as stage:
        save_series(stage / SERIES, result.series)
        if figures:
            metrics["figures"] = [f"{s}.png" for s in run_figures(
                result.series, result.metrics, stage, scenario.name)]
        if replay:
            write_replay(result.series, result.metrics, resolve_model(scenario.robot.model),
                         stage / "replay.html", conveyors=conveyor_belts(scenario),
                         end_effector=scenario.robot.end_effector)
        write_json_atomic(stage / METRICS, metrics)
    return metrics


def normalize_graphviz_ids(text: str) -> str:
    """Renumber Drake's system ids (a process-wide counter) in order of appearance and
    sort each run of edge lines (Drake emits them in an order that varies by process).

    The same diagram then exports to the same text in any process, so the
    committed ``diagrams/`` can be compared with a fresh export.
    """
    mapping: dict = {}

    def renumber(match):
        key = match.group(2)
        mapping.setdefault(key, str(len(mapping)))
        return match.group(1) + mapping[key]

    lines = re.sub(r"(\bs|\b_|cluster)(\d+)", renumber, text).split("\n")
    out, edges = [], []
    for line in lines + [""]:
        if " -> " in line:
            edges.append(line)
            continue
        out.extend(sorted(edges))
        edges = []
        out.append(line)
    return "\n".join(out[:-1])


def write_diagram(scenario: Scenario, out_dir: Path) -> list[Path]:
    """The built diagram as ``NAME.dot`` and ``NAME.svg`` (Graphviz's ``dot``)."""
    dot_exe = shutil.which("dot")
    if dot_exe is None:
        raise ScenarioError("diagram: Graphviz's `dot` is not installed (apt-get install graphviz)")
    diagram = build(scenario, log=False).diagram
    text = normalize_graphviz_ids(diagram.GetGraphvizString(max_depth=1))
    out_dir = Path(out_dir)
    with staged_output(out_dir, additive=True) as stage:  # one pair of files per scenario
        dot_path = stage / f"{scenario.name}.dot"
        dot_path.write_text(text)
        svg = subprocess.run([dot_exe, "-Tsvg", str(dot_path)], check=True,
                             capture_output=True, text=True).stdout
        (stage / f"{scenario.name}.svg").write_text(svg)
    return [out_dir / f"{scenario.name}.dot", out_dir / f"{scenario.name}.svg"]
