"""The figures ``ptint run`` draws for a pick and place (the replay: ``views``, which re-exports these).

``pick_figure`` — ``picks.png``: the run's verdict on top; per pick a block of four panels under
its outcome (grasp time against the prescribed, place error), over the task's time: the tool's distance to
the part (mm, log scale) and its angle from the top-down grasp (deg), the finger opening (mm) with
the grasp state the gripper reported (``systems.hand.gripper.GraspObserver``: open … lost, a step line),
the grip force (N): the measured contact force squeezing the part (the smaller of the two pads'
normal forces, as ``peak_grip_force_N``) with the drives' force thin beside it, and the part's
height (mm); each attempt's prescribed grasp time (dashed) and close command (dotted) marked.

``estimate_figure`` — ``estimates.png``, for a run with an RGB-D camera: per pick (a row, under
its fits' count and the estimate's error at the grasp), the
part's estimate (what the pick aimed at) minus the truth (the simulated part) over time — along
its belt and across it (mm) and in yaw (deg, folded by the part's symmetry) — with each fit the
estimators were given (dots, at the frame's time: the fit minus the truth then), the frames'
times (grey ticks) and the prescribed grasp time (dashed) marked, each in the legend; up to 0.3 s
past the grasp (after it the part is in the hand); the estimate is drawn from the first fit on
(before it the pick aims at the part's nominal place: how far off, a note on the panel) and the
stretch from the last fit to the grasp is shaded (the arm over the part hides it: no fit, the
estimate rides its belt); the vertical range is that from the first fit to the grasp.

Each block is drawn by its own function (``_pick_block``, ``_estimate_block``), each panel by one
of its own (``_tool_panel`` … ``_height_panel``; ``_estimate_panel``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

FONT_SIZE = 11  # pt, the pick figures' text (at 100 dpi: readable at the PNG's own size)


def pick_outcome(row: int, pick: dict) -> str:
    """One line: pick ``row``'s part and slot, its grasp time against the prescribed, its place."""
    grasp = ("never grasped" if pick["t_grasp"] is None else
             f"grasped at {pick['t_grasp']:.3f} s (prescribed {pick['t_grasp_prescribed']:.3f} s)")
    place = (f"placed {pick['place_error_mm']:.2f} mm, {pick['place_error_deg']:.2f}° from its slot"
             if pick["placed"] else "NOT placed")
    into = f"slot {pick['slot']}"
    if "bin" in pick:  # a bin: in it or not, no mm criterion
        place, into = ("in the bin" if pick["placed"] else "NOT in the bin"), f"bin {pick['bin']}"
    if "belt" in pick:  # an outgoing belt: on it, upright, or not (``out_belt.on_belt``), no mm criterion
        place, into = ("on the belt" if pick["placed"] else "NOT on the belt"), f"belt {pick['belt']}"
    attempts = len(pick.get("attempt_details") or [pick])
    retried = f" after {attempts} attempts" if attempts > 1 else ""
    return f"pick {row} ({pick['part']} → {into}): {grasp}{retried}, {place}"


def _mark_attempts(ax, pick: dict) -> None:
    """Each attempt's prescribed grasp time (dashed) and close command (dotted), labelled once."""
    for k, attempt in enumerate(pick.get("attempt_details") or [pick]):
        ax.axvline(attempt["t_grasp_prescribed"], color="k", ls="--", lw=0.9,
                   label="prescribed grasp" if k == 0 else None)
        ax.axvline(attempt["t_close_command"], color="tab:red", ls=":", lw=1.0,
                   label="close command" if k == 0 else None)


def _legend(ax, *others, loc: str = "best") -> None:
    """One legend for ``ax`` and its twin axes ``others``."""
    handles, labels = ax.get_legend_handles_labels()
    for other in others:
        h, lab = other.get_legend_handles_labels()
        handles, labels = handles + h, labels + lab
    ax.legend(handles, labels, fontsize=FONT_SIZE - 2, loc=loc, framealpha=0.85)


def pick_figure(series: dict, metrics: dict, path: Path, title: str = "") -> Path:
    """Draw ``picks.png`` (module docstring) from a pick run's series and metrics: per pick a
    block of four panels under its outcome (``pick_outcome``), the run's verdict on top."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    picks = metrics["picks"]
    with plt.rc_context({"font.size": FONT_SIZE}):
        fig = plt.figure(figsize=(13, 7.2 * len(picks) + 0.6 if picks else 2.0), layout="constrained")
        placed = sum(bool(p["placed"]) for p in picks)
        fig.suptitle(f"{title or metrics.get('scenario', '')}: {metrics.get('status', '')} — "
                     f"{placed} of {len(picks)} parts placed", fontsize=FONT_SIZE + 3, fontweight="bold")
        if not picks:  # a line that decided no task (nothing entered, nothing seen)
            codes = sorted({r["code"] for r in metrics.get("reason_codes", [])})
            fig.text(0.5, 0.4, "no pick was made" + (f": {', '.join(codes)}" if codes else ""),
                     ha="center", va="center", fontsize=FONT_SIZE + 1)
        else:
            blocks = np.atleast_1d(fig.subfigures(len(picks), 1))
            for row, (block_fig, pick) in enumerate(zip(blocks, picks)):
                _pick_block(block_fig, row, pick, series)
        fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _pick_block(block_fig, row: int, pick: dict, series: dict) -> None:
    """Pick ``row``'s block of ``picks.png``: its outcome over four panels (one function each)."""
    from ptint_drake.worlds.pick.probe import PART_WIDTH  # noqa: PLC0415

    t, probe = series["t"], series["probe"]
    block_fig.suptitle(pick_outcome(row, pick), fontsize=FONT_SIZE + 1)
    axes = block_fig.subplots(2, 2, sharex=True).ravel()
    k = pick["part_index"]
    block = probe[:, PART_WIDTH * k: PART_WIDTH * (k + 1)]
    _tool_panel(axes[0], t, probe, block, row, pick)  # the tool's distance to the part and its angle
    _fingers_panel(axes[1], t, series, row, pick)  # the fingers
    _grip_panel(axes[2], t, series, k, row, pick)  # the grip
    _height_panel(axes[3], t, block, row, pick)  # the part's height
    for ax in axes[2:]:
        ax.set_xlabel("t (s)")


def _tool_panel(ax, t: np.ndarray, probe: np.ndarray, block: np.ndarray, row: int, pick: dict) -> None:
    """The tool's distance to the part (mm, log) and, on a twin axis, its angle from the top-down
    grasp (deg); ``block``: the part's columns of the probe."""
    from ptint_drake.worlds.pick.metrics import rotation_of  # noqa: PLC0415

    distance = 1e3 * np.linalg.norm(block[:, 0:3] - probe[:, -7:-4], axis=1)
    x_axis = [1.0, 0.0, 0.0]
    angle = np.array([np.degrees(np.arccos(np.clip(
        (rotation_of(probe[j, -4:]) @ x_axis) @ (rotation_of(block[j, 3:7]) @ x_axis), -1.0, 1.0)))
        for j in range(len(t))])
    angle = np.minimum(angle, 180.0 - angle)  # the fingers' axis: a half turn is the same grasp
    ax.plot(t, np.maximum(distance, 1e-3), lw=1.3, label="tool to part")
    ax.set_yscale("log")
    ax.set_ylabel("tool to part (mm, log)")
    twin = ax.twinx()
    twin.plot(t, angle, color="tab:orange", lw=1.0, label="angle from the top-down grasp")
    twin.set_ylabel("angle (deg)", color="tab:orange")
    _mark_attempts(ax, pick)
    ax.set_title(f"pick {row} ({pick['part']}): tool to part and its angle")
    _legend(ax, twin, loc="upper right")


def _fingers_panel(ax, t: np.ndarray, series: dict, row: int, pick: dict) -> None:
    """The finger opening (mm) and, on a twin axis, the grasp state the gripper reported."""
    opening = 1e3 * (series["gripper_state"][:, 0] + series["gripper_state"][:, 1])
    ax.plot(t, opening, lw=1.3, label="finger opening")
    ax.set_ylabel("opening (mm)")
    others = []
    if "grasp_state" in series:
        state = ax.twinx()
        _state_line(state, t, series["grasp_state"])
        others.append(state)
    _mark_attempts(ax, pick)
    ax.set_title(f"pick {row} ({pick['part']}): finger opening, grasp state")
    _legend(ax, *others, loc="center right")


def _grip_panel(ax, t: np.ndarray, series: dict, k: int, row: int, pick: dict) -> None:
    """The contact grip on part ``k`` (the smaller pad force, N) and the drives' force (thin)."""
    contact = np.min(series["grip_forces"][:, 2 * k: 2 * k + 2], axis=1)  # what squeezes the part
    drive = -np.mean(series["grip_force"], axis=1)
    ax.plot(t, contact, lw=1.3, label="contact grip (smaller pad force)")
    ax.plot(t, drive, color="0.6", lw=0.8, label="drives' force")
    ax.set_ylabel("force (N)")
    _mark_attempts(ax, pick)
    ax.set_title(f"pick {row} ({pick['part']}): contact grip force (N)")
    _legend(ax, loc="center left")


def _height_panel(ax, t: np.ndarray, block: np.ndarray, row: int, pick: dict) -> None:
    """The part's height (mm); ``block``: the part's columns of the probe."""
    ax.plot(t, 1e3 * block[:, 2], lw=1.3, label="part's height")
    ax.set_ylabel("height (mm)")
    _mark_attempts(ax, pick)
    ax.set_title(f"pick {row} ({pick['part']}): part height (mm)")
    _legend(ax, loc="upper right")


GRASP_TAIL = 0.3  # s, drawn past a pick's prescribed grasp in estimates.png


def _yaw(block: np.ndarray) -> np.ndarray:
    """The yaw of the row-major rotations in columns 3:12 of [x (3), R (9)] rows."""
    return np.arctan2(block[:, 6], block[:, 3])


def estimate_figure(series: dict, metrics: dict, directions: list, symmetries: list, path: Path,
                    title: str = "") -> Path:
    """Draw ``estimates.png`` (module docstring); ``directions``: per part its belt's unit
    direction, ``symmetries``: per part its yaw symmetry (rad; 0: none known, ``part_fit.yaw_symmetry``).
    The estimate is drawn from the first fit on (before it the pick aims at the part's nominal
    place: how far off that is is written on the panel); the stretch from the last fit to the
    grasp, where the arm over the part hides it and the estimate rides its belt, is shaded."""
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    t, picks = np.asarray(series["t"]), metrics["picks"]
    with plt.rc_context({"font.size": FONT_SIZE}):
        fig = plt.figure(figsize=(14, 4.6 * len(picks) + 0.6), layout="constrained")
        fig.suptitle(f"{title or metrics.get('scenario', '')}: {metrics.get('status', '')} — the part's "
                     "estimate (what the pick aims at) minus the simulated part", fontsize=FONT_SIZE + 2,
                     fontweight="bold")
        blocks = np.atleast_1d(fig.subfigures(len(picks), 1))
        for row, (block_fig, pick) in enumerate(zip(blocks, picks)):
            k = pick["part_index"]
            _estimate_block(block_fig, row, pick, t, series, directions[k], symmetries[k])
        fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _estimate_errors(t: np.ndarray, series: dict, k: int, direction, symmetry: float) -> tuple:
    """Part ``k``'s (panels, stamps): per panel (label, unit, estimate − truth at ``t``, each fit −
    truth at its frame's time) — along its belt (``direction``), across it, in yaw (folded by
    ``symmetry``) — and the valid fits' frame times."""
    from ptint_drake.systems.perception.part_fit import fold_yaw  # noqa: PLC0415

    true, estimate, fit = (np.asarray(series[f"{name}_{k}"])
                           for name in ("part_true", "part_estimate", "fit"))
    u = np.asarray(direction, float)
    across = np.array([-u[1], u[0], 0.0])
    error = estimate[:, 0:3] - true[:, 0:3]
    stamps, first = np.unique(fit[:, 0], return_index=True)
    valid = fit[first, 4] > 0.5
    stamps, first = stamps[valid], first[valid]
    at = np.searchsorted(t, stamps).clip(0, len(t) - 1)  # the truth at each frame's time
    fit_error = fit[first, 1:4] - true[at, 0:3]
    # R[1, 0], R[0, 0] after [stamp, x, y, z, valid]
    fit_yaw = np.arctan2(fit[first, 8], fit[first, 5])
    dyaw, fit_dyaw = _yaw(estimate) - _yaw(true), fit_yaw - _yaw(true[at])
    # (a part of any yaw, symmetry 0: fold_yaw's 0 for each)
    yaw_error = np.degrees(fold_yaw(dyaw, symmetry) + 0.0 * dyaw)
    fit_yaw_error = np.degrees(fold_yaw(fit_dyaw, symmetry) + 0.0 * fit_dyaw)
    panels = (("along the belt", "mm", 1e3 * error @ u, 1e3 * fit_error @ u),
              ("across the belt", "mm", 1e3 * error @ across, 1e3 * fit_error @ across),
              ("yaw", "deg", yaw_error, fit_yaw_error))
    return panels, stamps


def _estimate_block(block_fig, row: int, pick: dict, t: np.ndarray, series: dict, direction,
                    symmetry: float) -> None:
    """Pick ``row``'s row of ``estimates.png``: its fits and error at the grasp over three panels
    (``_estimate_panel``), the legend beside the last."""
    axes = block_fig.subplots(1, 3)
    panels, stamps = _estimate_errors(t, series, pick["part_index"], direction, symmetry)
    grasp = pick["t_grasp_prescribed"]
    keep = t <= grasp + GRASP_TAIL
    shown = stamps <= grasp + GRASP_TAIL
    first_fit = stamps[0] if len(stamps) else None
    last_fit = stamps[shown][-1] if np.any(shown) else None
    fitted = keep & (t >= (first_fit if first_fit is not None else np.inf))
    at_grasp = ("never fitted" if pick.get("estimate_error_mm") is None else
                f"at the grasp {pick['estimate_error_mm']:.2f} mm, "
                f"{pick['estimate_error_deg']:.2f}° off")
    block_fig.suptitle(f"pick {row} ({pick['part']}): {len(stamps[shown])} fits, the estimate "
                       f"{at_grasp}; {'placed' if pick['placed'] else 'NOT placed'}",
                       fontsize=FONT_SIZE + 1)
    for ax, panel in zip(axes, panels):
        _estimate_panel(ax, panel, t, fitted, stamps, shown, grasp, first_fit, last_fit)
    _estimate_legend(axes)


def _estimate_panel(ax, panel: tuple, t: np.ndarray, fitted: np.ndarray, stamps: np.ndarray,
                    shown: np.ndarray, grasp: float, first_fit, last_fit) -> None:
    """One panel: ``panel`` = (label, unit, estimate − truth, each fit − truth) drawn where
    ``fitted``, the fits at their frames' times ``stamps`` where ``shown``, the frames' ticks, the
    stretch without a fit shaded, the grasp dashed, and the note on the nominal place."""
    label, unit, values, fits = panel
    ax.plot(t[fitted], values[fitted], lw=1.3, label="estimate − truth")
    ax.plot(stamps[shown], fits[shown], ".", ms=4, color="tab:orange", label="each fit − truth")
    if np.any(fitted):
        lo, hi = np.percentile(np.r_[values[fitted & (t <= grasp)], fits[shown]], [1, 99])
        pad = max(0.25 * (hi - lo), 0.2)
        ax.set_ylim(min(lo, 0.0) - pad, max(hi, 0.0) + pad)
    ax.axhline(0.0, color="0.5", lw=0.5)
    for s_ in stamps[shown]:
        ax.axvline(s_, ymin=0.0, ymax=0.04, color="0.4", lw=0.7)
    if last_fit is not None and last_fit < grasp:
        ax.axvspan(last_fit, grasp, color="0.92", zorder=0)
    ax.axvline(grasp, color="k", ls="--", lw=0.9)
    if first_fit is not None and first_fit > t[0]:
        before = values[0]
        ax.text(0.02, 0.97, f"before the first fit ({first_fit:.2f} s):\nthe nominal place, "
                f"{before:+.1f} {unit}", transform=ax.transAxes, va="top", fontsize=FONT_SIZE - 2,
                color="0.3")
    ax.set_title(f"estimate error {label} ({unit})")
    ax.set_ylabel(f"{label} ({unit})")
    ax.set_xlabel("t (s)")
    ax.set_xlim(t[0], grasp + GRASP_TAIL)


def _estimate_legend(axes) -> None:
    """The row's legend, beside its last panel: the first panel's lines and the marks explained
    (a frame's tick, the prescribed grasp, the shaded stretch without a fit)."""
    import matplotlib  # noqa: PLC0415
    from matplotlib.lines import Line2D  # noqa: PLC0415

    extra = [Line2D([], [], color="0.4", marker="|", ls="none", ms=10,
                    label="a camera frame fitted"),
             Line2D([], [], color="k", ls="--", lw=0.9, label="prescribed grasp"),
             matplotlib.patches.Patch(color="0.92", label="no fit: the arm hides the part,\n"
                                      "the estimate rides its belt")]
    handles, labels = axes[0].get_legend_handles_labels()
    axes[-1].legend(handles + extra, labels + [h.get_label() for h in extra],
                    fontsize=FONT_SIZE - 2, loc="upper left", bbox_to_anchor=(1.02, 1.0))


def _state_line(ax, t: np.ndarray, codes: np.ndarray) -> None:
    """The gripper's reported grasp state over time, a step line on its own axis (open … lost)."""
    from ptint_drake.systems.hand.gripper import GRASP_STATES  # noqa: PLC0415

    ax.step(t, codes, where="post", color="tab:green", lw=0.9, label="grasp state (right axis)")
    ax.set_yticks(range(len(GRASP_STATES)), GRASP_STATES, fontsize=FONT_SIZE - 2, color="tab:green")
    ax.set_ylim(-0.5, len(GRASP_STATES) - 0.5)
    ax.set_ylabel("grasp state", color="tab:green")
