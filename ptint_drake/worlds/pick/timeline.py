"""The timeline of each part of a pick run (issue 44): ``timeline.png``, one row per part, with its
events read from what the run recorded — nothing is simulated or measured again.

``part_timelines`` — per declared part a ``PartTimeline``:

- ``seen``: with an RGB-D camera, the frame time of the first fit the part's track took (the
  track bound to the part in the perception's tracks log, series ``tracks_t`` / ``tracks``:
  ``systems.perception.track_system``), None when no track was ever bound to it; without a
  camera (the parts' poses are given by the tracker sensor from the start) 0; on a line, its
  ``seen`` in metrics.json ``line.parts`` (``line.metrics``: the camera's first fit of it, or with
  the pose sensor its release);
- ``scheduled``: its task's start (the task's first approach, or the via before it), from
  metrics.json's ``segments``; None for a part no task picks;
- ``grasped``: the pick's ``t_grasp`` (both pads on the part in its last attempt; None: never);
- ``placed``: the end of the task's place segment (its prescribed time), when the pick is
  ``placed``;
- ``failed``: the verdict's reasons of its task (metrics.json's ``reason_codes``, ``pick k: …``),
  and ``ended``: the task's last segment's end, where a failure is marked.

``timeline_figure`` draws them: per part a line from its first event to its last, the events as
marks (seen, scheduled, grasped, placed; a failure as a red cross with its reasons written
beside it), the run's duration as the horizontal range.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from ptint_drake.systems.perception.track_system import ROW
from ptint_drake.systems.perception.tracks import MAX_TRACKS

FONT_SIZE = 11  # pt
MARKS = {"seen": ("o", "tab:blue"), "scheduled": (">", "tab:orange"), "grasped": ("s", "tab:purple"),
         "placed": ("*", "tab:green")}


@dataclass
class PartTimeline:
    """One part's events (s; module docstring)."""

    name: str
    seen: Optional[float] = None
    scheduled: Optional[float] = None
    grasped: Optional[float] = None
    placed: Optional[float] = None
    ended: Optional[float] = None
    failed: list = field(default_factory=list)

    def events(self) -> dict:
        """{event: time} of the events that happened, in the order of ``MARKS``."""
        return {name: getattr(self, name) for name in MARKS if getattr(self, name) is not None}


def first_track_fit(tracks, part: int) -> Optional[float]:
    """The frame time of the first fit taken by the track bound to declared ``part`` in the
    perception's tracks log (rows: [stamp, per slot: id, bound part, took a fit, x, y, z,
    class]); None when no track was bound to it."""
    rows = np.asarray(tracks)
    slots = rows[:, 1:].reshape(len(rows), MAX_TRACKS, ROW)
    bound = slots[(slots[:, :, 0] > 0) & (np.rint(slots[:, :, 1]) == part)]
    if not len(bound):
        return None
    track = bound[0, 0]
    took = (slots[:, :, 0] == track) & (slots[:, :, 2] > 0.5)
    frames = np.flatnonzero(np.any(took, axis=1))
    return float(rows[frames[0], 0]) if len(frames) else None


def task_reasons(metrics: dict) -> dict:
    """{task: [reason codes]} from metrics.json's ``reason_codes`` (the pick world's messages are
    ``pick k: code``)."""
    out: dict = {}
    for reason in metrics.get("reason_codes", []):
        found = re.match(r"pick (\d+): ", reason.get("message", ""))
        if found:
            out.setdefault(int(found.group(1)), []).append(reason["code"])
    return out


def part_timelines(names: list[str], series: dict, metrics: dict, camera: bool) -> list[PartTimeline]:
    """Per declared part (``names``, in order) its ``PartTimeline`` (module docstring); a line's
    parts are those its run released (the first of the pool, in release order: a draw that released
    none keeps one part parked, ``line.arrivals.idle_part``)."""
    rows = metrics.get("line", {}).get("parts")  # a line: when each part was seen (``line.metrics``)
    lines = [PartTimeline(name) for name in (names if rows is None else names[:len(rows)])]
    for k, line in enumerate(lines):
        if rows is not None:
            line.seen = rows[k]["seen"]
            if rows[k].get("task") is None and rows[k].get("reason"):  # lost with no task (``line.metrics``)
                line.failed, line.ended = [rows[k]["reason"]], rows[k].get("failed_at")
        elif not camera:
            line.seen = 0.0
        elif "tracks" in series:
            line.seen = first_track_fit(series["tracks"], k)
    reasons = task_reasons(metrics)
    for task, pick in enumerate(metrics["picks"]):
        line = lines[pick["part_index"]]
        rows = [s for s in metrics["segments"] if s["task"] == task]
        line.scheduled = float(min(s["start"] for s in rows))
        line.ended = float(max(s["start"] + s["tf"] for s in rows))
        line.grasped = None if pick["t_grasp"] is None else float(pick["t_grasp"])
        if pick["placed"]:
            place = [s for s in rows if s["phase"] == "place"][-1]
            line.placed = float(place["start"] + place["tf"])
        line.failed = list(reasons.get(task, []))
    return lines


def timeline_figure(lines: list[PartTimeline], metrics: dict, path: Path, title: str = "") -> Path:
    """Draw ``timeline.png`` (module docstring) from ``part_timelines``."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    end = float(metrics.get("duration") or max([e for tl in lines for e in tl.events().values()] + [1.0]))
    with plt.rc_context({"font.size": FONT_SIZE}):
        fig, ax = plt.subplots(figsize=(12, 1.2 + 0.7 * max(len(lines), 1)), layout="constrained")
        placed = sum(tl.placed is not None for tl in lines)
        fig.suptitle(f"{title or metrics.get('scenario', '')}: {metrics.get('status', '')} — {placed} of "
                     f"{len(lines)} parts placed", fontsize=FONT_SIZE + 2, fontweight="bold")
        for row, line in enumerate(lines):
            _timeline_row(ax, row, line, end)
        ax.set_yticks(range(len(lines)), [tl.name for tl in lines])
        ax.set_ylim(max(len(lines), 1) - 0.5, -0.5)  # the first part on top
        if not lines:
            ax.text(0.5 * end, 0.0, "no part arrived", ha="center", va="center", color="0.4")
        ax.set_xlim(0.0, end)
        ax.set_xlabel("t (s)")
        ax.set_title("each part: seen → scheduled → grasped → placed, or failed (why)")
        ax.grid(axis="x", color="0.9")
        handles, labels = ax.get_legend_handles_labels()
        unique = dict(zip(labels, handles))
        ax.legend(unique.values(), unique.keys(), fontsize=FONT_SIZE - 2, loc="upper left",
                  bbox_to_anchor=(1.01, 1.0))
        fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _timeline_row(ax, row: int, line: PartTimeline, end: float) -> None:
    """One part's row: a line over its events, each event's mark, a failure's cross and reasons
    (written to the cross's left in the last third of the run's ``end``, inside the axes)."""
    events = line.events()
    times = list(events.values()) + ([line.ended] if line.failed and line.ended is not None else [])
    if len(times) > 1:
        ax.plot([min(times), max(times)], [row, row], color="0.6", lw=1.5, zorder=1)
    for name, t in events.items():
        marker, color = MARKS[name]
        hollow = {"markerfacecolor": "none", "ms": 15, "mew": 2} if name == "seen" else {"ms": 10}
        ax.plot([t], [row], marker=marker, color=color, ls="none", label=name, zorder=3, **hollow)
    if line.failed:
        t = line.ended if line.ended is not None else (max(times) if times else 0.0)
        ax.plot([t], [row], marker="X", color="tab:red", ms=11, ls="none", label="failed", zorder=3)
        late = t > 2.0 * end / 3.0
        ax.annotate("failed: " + ", ".join(line.failed), (t, row), xytext=(-8 if late else 8, 8),
                    textcoords="offset points", color="tab:red", fontsize=FONT_SIZE - 1,
                    ha="right" if late else "left")
    elif not events:
        ax.annotate("never seen, no task", (0.0, row), xytext=(4, 0), textcoords="offset points",
                    color="0.4", fontsize=FONT_SIZE - 1, va="center")
