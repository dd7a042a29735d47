"""The plugin example both plugin test files use: the README's task-space PD
(``examples/task_space_pd.py``) and a short scenario that runs it (``SCENARIO % TYPE``)."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "task_space_pd.py"
TYPE = "task_space_pd:TaskSpacePD"

SCENARIO = """duration: 1.6
controller: {type: "%s", params: {Kp: 2000.0, Kd: 150.0}}
interceptions:
  - start: 0.0
    tf: 1.0
    beta: 0.75
    target: {linear: {start: [0.30, -0.05, 0.25], velocity: [0.0, 0.05, 0.0]}}
"""
