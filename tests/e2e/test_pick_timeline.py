"""Issue 44: ``timeline.png`` — per part when it was seen, scheduled, grasped and placed (or why it
failed), read from what the run recorded: metrics.json's segments, picks and reasons, and with a
camera the perception's tracks log (the first fit the part's track took)."""

from pathlib import Path

import numpy as np
import pytest

from ptint_drake.report.run_outputs import write_views
from ptint_drake.systems.perception.tracks import CONFIRM
from ptint_drake.worlds.pick.timeline import part_timelines

TWO_PARTS = str(Path(__file__).resolve().parents[1] / "two_parts_one_belt.yaml")


def _task_times(metrics: dict, task: int) -> tuple[float, float]:
    """(the task's first segment's start, its place's prescribed time) from metrics.json."""
    rows = [s for s in metrics["segments"] if s["task"] == task]
    place = next(s for s in rows if s["phase"] == "place")
    return rows[0]["start"], place["start"] + place["tf"]


def test_a_pick_run_writes_its_timeline_with_the_events_of_its_metrics(run, tmp_path):
    result = run("conveyor_pick_place")
    metrics = result.metrics
    stems = write_views(result.scenario, result.series, metrics, tmp_path, figures=True, replay=False,
                        workers=1)
    assert "timeline" in stems and (tmp_path / "timeline.png").stat().st_size > 10_000
    [line] = part_timelines([p.name for p in result.scenario.pick.parts], result.series, metrics, False)
    scheduled, placed = _task_times(metrics, 0)
    assert line.seen == 0.0  # the pose sensor gives the part from the start
    assert line.scheduled == scheduled and line.grasped == metrics["picks"][0]["t_grasp"]
    assert line.placed == pytest.approx(placed) and line.failed == []
    assert line.seen <= line.scheduled < line.grasped < line.placed


@pytest.mark.slow
def test_a_camera_part_is_seen_at_its_tracks_first_fit_and_each_task_in_turn(run):
    result = run(TWO_PARTS, ())
    series, metrics = result.series, result.metrics
    period = 1.0 / result.scenario.measurement.rate_hz
    lines = part_timelines(["first", "second"], series, metrics, True)
    for task, pick in enumerate(metrics["picks"]):
        k = pick["part_index"]
        line = lines[k]
        fit = np.asarray(series[f"fit_{k}"])
        given = fit[fit[:, 4] > 0.5, 0].min()  # the part's first fit: once its track is confirmed
        assert line.seen is not None and line.seen <= given <= line.seen + (CONFIRM - 1) * period + 1e-6
        scheduled, placed = _task_times(metrics, task)
        assert line.scheduled == scheduled and line.grasped == pick["t_grasp"]
        assert line.placed == pytest.approx(placed) and line.failed == []
    assert lines[1].scheduled >= lines[0].placed  # the second task after the first's place
