"""Matplotlib figures of a run and of the TBG families (paper Figs. 2-4, 6-19).

Every figure is written as PNG (and SVG when asked), with units, legends and the
prescribed interception time(s) marked by dashed vertical lines.  Robot accelerations
and jerks are Savitzky–Golay derivatives (21 ms window) of the logged Cartesian
velocity resampled on a uniform 1 ms grid (the integrator's steps are not uniform;
``derivatives.py``).

What a figure costs is what it shows: matplotlib is imported when a figure is drawn
(not with this module; ``pyplot`` only for the studies that ask for ``figures.plt``), a
line is drawn with at most two points (its minimum and maximum) per pixel column
(``envelope``), the run's grids are laid out by measuring them once (``figure_grid``), and
a laid-out figure is drawn once, at the PNG's resolution, its pixels the PNG (``save``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ptint_drake.systems.task.tbg import alpha_gain, tbg_profile
from ptint_drake.views.derivatives import uniform_derivatives
from ptint_drake.views.plot_grid import place_grid
from ptint_drake.views.plot_marks import mark_peak, peak_label, peak_of, robust_limit

AXES = ("X", "Y", "Z")
FORMATS = ("png", "svg")
DPI = 120


def __getattr__(name: str):
    """``figures.plt``: pyplot, imported (with the Agg backend) by the studies that use it."""
    if name == "plt":
        import matplotlib  # noqa: PLC0415

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt  # noqa: PLC0415

        return plt
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def new_figure(figsize, **kwargs):
    """A matplotlib ``Figure`` outside pyplot (nothing to close, no pyplot import) at ``DPI``."""
    from matplotlib.figure import Figure  # noqa: PLC0415

    return Figure(figsize=figsize, dpi=DPI, **kwargs)


_PRELOADED: set = set()


def preload(studies: bool = False) -> None:
    """Import what drawing a run's figures needs (matplotlib's figure, Agg and 3D axes,
    Pillow) and draw the kinds of text the run figures show (mathtext, each
    font size), so the font lookups and the mathtext parser are made once: worker processes
    forked afterwards share all of it.  ``studies``: pyplot too.  Once per process."""
    if studies and "studies" not in _PRELOADED:
        _PRELOADED.add("studies")
        __getattr__("plt")
    if "figures" in _PRELOADED:
        return
    _PRELOADED.add("figures")
    import matplotlib.backends.backend_agg  # noqa: PLC0415
    import matplotlib.figure  # noqa: F401, PLC0415
    import mpl_toolkits.mplot3d  # noqa: F401, PLC0415
    import PIL.Image  # noqa: F401, PLC0415

    fig = new_figure((2, 1))
    for size in (7, 8, 9, 10, 12):
        fig.text(0.0, 0.0, "|e($t_f$)| $\\mathdefault{10^{-3}}$ m/s² ξ̇ τ θ° −", fontsize=size)
    matplotlib.backends.backend_agg.FigureCanvasAgg(fig).draw()


def envelope(x: np.ndarray, y: np.ndarray, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) with at most the first, the last, and the smallest and largest y of each of
    ``columns`` equal slices of x's range, in x order: a line through them covers the same
    pixels as the whole series when the line is ``columns`` pixels wide (or wider)."""
    n = len(x)
    if n <= 4 * columns or columns < 1:
        return x, y
    span = (x[-1] - x[0]) or 1.0
    col = np.minimum(((x - x[0]) / span * columns).astype(int), columns - 1)
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    order = np.lexsort((y, col))  # by column, then by value: each column's min first, max last
    keep = np.zeros(n, dtype=bool)
    keep[[0, n - 1]] = True
    keep[order[starts]] = True
    keep[order[np.r_[starts[1:], n] - 1]] = True
    return x[keep], y[keep]


def save(fig, out_dir: Path, stem: str, formats=FORMATS, laid_out: bool = False) -> list[Path]:
    """Write ``stem.png`` (and ``stem.svg`` when in ``formats``) in ``out_dir``; returns the paths.

    A figure with a constrained layout, or ``laid_out`` already (``figure_grid.place_grid``),
    is drawn once at ``DPI`` and its pixels written as the PNG; the SVG (on request) reuses
    that layout.  Other figures are cropped to their contents (``bbox_inches="tight"``).
    """
    from matplotlib.layout_engine import ConstrainedLayoutEngine  # noqa: PLC0415

    paths = [Path(out_dir) / f"{stem}.{ext}" for ext in formats]
    if laid_out or isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine):
        _save_laid_out(fig, paths)
    else:
        for path in paths:
            fig.savefig(path, dpi=DPI if path.suffix == ".png" else None, bbox_inches="tight")
    import sys  # noqa: PLC0415

    if "matplotlib.pyplot" in sys.modules:  # a figure the studies made with pyplot
        sys.modules["matplotlib.pyplot"].close(fig)
    return paths


def _save_laid_out(fig, paths) -> None:
    """One draw at ``DPI`` (layout included), its pixels as the PNG (RGB when every pixel is
    opaque); then the layout frozen for the vector formats."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: PLC0415
    from PIL import Image  # noqa: PLC0415

    fig.set_dpi(DPI)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    rgba = np.asarray(canvas.buffer_rgba())
    pixels = rgba[..., :3] if rgba[..., 3].min() == 255 else rgba  # opaque: RGB, the same image
    for path in paths:
        if path.suffix == ".png":  # zlib level 1: a third of the default's time, about its size
            Image.fromarray(pixels).save(path, format="png", dpi=(DPI, DPI), compress_level=1)
    fig.set_layout_engine("none")
    for path in paths:
        if path.suffix != ".png":
            fig.savefig(path)


def _mark_times(ax, times):
    for i, t in enumerate(times):
        ax.axvline(t, color="k", ls="--", lw=0.8, label="prescribed time $t_f$" if i == 0 else None)


def tbg_family_figure(settings, out_dir: Path, stem: str, title: str, n: int = 2000,
                      formats=("png",)):
    """ξ, ξ̇, ξ̈, ξ⃛ and α(t) for a list of (tf, β) settings (paper Figs. 2-4).

    The time grid is refined geometrically towards each tf, where α peaks.  ξ̈ is
    unbounded for β < 1/2 and ξ⃛ for β < 2/3: their axes are scaled to the bounded
    curves and the unbounded ones run off the plot (as in the paper).
    Returns the sampled data {label: dict(t, xi, xi_dot, xi_ddot, xi_dddot, alpha, tf, beta)}.
    """
    fig = new_figure((7, 11), layout="constrained")
    axes = fig.subplots(5, 1, sharex=True)
    data = {}
    t_max = max(tf for tf, _ in settings) * 1.15
    limits = {2: [0.0], 3: [0.0]}
    for tf, beta in settings:
        t = np.unique(np.concatenate([np.linspace(0.0, t_max, n),
                                      tf * (1.0 - np.logspace(-12, 0, n))]))
        xi, xd, xdd, xddd = tbg_profile(t, tf, beta)
        alpha = np.where(t < tf, alpha_gain(xi, xd), 0.0)
        label = f"β = {beta}, $t_f$ = {tf} s"
        data[label] = dict(t=t, xi=xi, xi_dot=xd, xi_ddot=xdd, xi_dddot=xddd, alpha=alpha, tf=tf, beta=beta)
        for ax, y in zip(axes, (xi, xd, xdd, xddd, alpha)):
            ax.plot(*envelope(t, y, _columns(fig)), label=label)
        if beta >= 0.5:
            limits[2].append(np.max(np.abs(xdd)))
        if beta >= 2.0 / 3.0:
            limits[3].append(np.max(np.abs(xddd)))
    names = ("ξ [-]", "ξ̇ [1/s]", "ξ̈ [1/s²]", "ξ⃛ [1/s³]", "α [1/s]")
    for ax, name in zip(axes, names):
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
    for k in (2, 3):
        if max(limits[k]) > 0:
            axes[k].set_ylim(-1.3 * max(limits[k]), 1.3 * max(limits[k]))
    axes[4].set_yscale("log")
    alpha_max = max(float(np.max(d["alpha"])) for d in data.values())
    axes[4].set_ylim(1e-2, 3.0 * alpha_max)
    _mark_times(axes[0], sorted({tf for tf, _ in settings}))
    for ax in axes[1:]:
        _mark_times(ax, sorted({tf for tf, _ in settings}))
    axes[0].legend(fontsize=7)
    axes[-1].set_xlabel("time since segment start [s]")
    fig.suptitle(title)
    save(fig, out_dir, stem, formats)
    return data


def _columns(fig, ncols: int = 1) -> int:
    """Pixel columns of one of ``ncols`` side-by-side axes in ``fig`` (an upper bound)."""
    return int(fig.get_figwidth() * DPI / ncols)


def run_figures(series: dict, metrics: dict, out_dir: Path, title: str, formats=("png",)) -> list[str]:
    """Per-axis robot vs target (position, velocity, acceleration, jerk), the error
    (against the true target), the per-axis velocity error (Fig. 16), torques, joint
    trajectories and the 3D paths.  Returns the stems written."""
    for stem in RUN_FIGURES:
        run_figure(stem, series, metrics, out_dir, title, formats)
    return list(RUN_FIGURES)


def run_figure(stem: str, series: dict, metrics: dict, out_dir: Path, title: str,
               formats=("png",)) -> str:
    """The run figure ``stem`` (of ``RUN_FIGURES`` or ``ORIENTATION_FIGURES``) written in
    ``out_dir``, its title ``title (verdict)``; returns ``stem``.  Module-level, so that a worker
    process can draw one figure while another draws the next."""
    tfs = [s["start"] + s["tf"] for s in metrics["segments"]]
    if metrics.get("status"):  # every run figure's title carries the run's verdict
        title = f"{title} ({metrics['status']})"
    (RUN_FIGURES | ORIENTATION_FIGURES)[stem](series, metrics, tfs, out_dir, title, formats)
    return stem


def _axes_figure(series: dict, metrics: dict, tfs, out_dir: Path, title: str, formats) -> None:
    t = series["t"]
    t_u, v, a, j = uniform_derivatives(t, series["xdot"])
    x_u = np.column_stack([np.interp(t_u, t, series["x"][:, k]) for k in range(3)])
    xr_u = np.column_stack([np.interp(t_u, t, series["x_r"][:, k]) for k in range(3)])
    _, vr, ar, jr = uniform_derivatives(t, series["xdot_r"])
    fig = new_figure((12, 10.5))
    axes = fig.subplots(4, 3, sharex=True)
    rows = (("position", "m", x_u, xr_u), ("velocity", "m/s", v, vr),
            ("acceleration", "m/s²", a, ar), ("jerk", "m/s³", j, jr))
    for r, (name, unit, robot, target) in enumerate(rows):
        for k in range(3):
            ax = axes[r, k]
            ax.plot(*envelope(t_u, robot[:, k], _columns(fig, 3)), label="robot")
            ax.plot(*envelope(t_u, target[:, k], _columns(fig, 3)), "--", label="target")
            _mark_times(ax, tfs)
            ax.grid(alpha=0.3)
            if r == 0:
                ax.set_title(AXES[k], y=1.0)  # where it goes (no offset text to avoid there)
            if k == 0:
                ax.set_ylabel(f"{name} [{unit}]")
            if r >= 2:  # linear axes scaled to the curves; the robot's peak marked with its time
                limit = robust_limit(robot[:, k], target[:, k])
                ax.set_ylim(-limit, limit)
                t_pk, val = peak_of(t_u, robot[:, k])
                off = abs(val) > limit
                h = mark_peak(ax, t_pk, val, limit, color="tab:red")
                ax.legend([h], [peak_label("", t_pk, val, unit) + (" (off scale)" if off else "")],
                          loc="best", fontsize=7, handletextpad=0.3, borderpad=0.3)
    for k in range(3):
        axes[-1, k].set_xlabel("time [s]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    legend = fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=9)
    place_grid(fig, axes, fig.suptitle(f"{title}: robot vs target per axis"), legend)
    save(fig, out_dir, "axes", formats, laid_out=True)


def _errors_figure(series: dict, metrics: dict, tfs, out_dir: Path, title: str, formats) -> None:
    t = series["t"]
    fig = new_figure((10, 8.5))
    axes = fig.subplots(3, 1, sharex=True)
    e_norm = np.linalg.norm(series["e_true"], axis=1)
    width = _columns(fig)
    axes[0].semilogy(*envelope(t, np.maximum(e_norm, 1e-9), width), label="|e|")
    bound = metrics.get("criteria", {}).get("e_tf", 1e-3)
    axes[0].axhline(bound, color="r", lw=0.8, label=f"{bound * 1e3:g} mm")
    e_tf = [s_["e_tf_norm"] for s_ in metrics["segments"]]
    hit = [v is not None and v <= bound for v in e_tf]
    reached = [(tf, v) for tf, v in zip(tfs, e_tf) if v is not None]
    if reached:
        axes[0].plot(*zip(*reached), ls="none", marker="o", mfc="none", color="k", ms=7,
                     label="|e($t_f$)|")
    values = ", ".join("n/a" if v is None else f"{v * 1e3:.3g}" for v in e_tf)
    status = metrics.get("status")
    if status is not None:  # the run's verdict (late, early, hold), not e(tf) alone
        verdict = "intercepted" if status == "ok" else f"{status.upper()} ({', '.join(metrics['reasons'])})"
    else:
        verdict = "intercepted" if all(hit) else f"{len(hit) - sum(hit)} of {len(hit)} late"
    axes[0].set_title(f"|e($t_f$)| = {values} mm (criterion ≤ {bound * 1e3:g} mm): {verdict}",
                      fontsize=10, y=1.0)
    axes[0].set_ylabel("|e| [m]")
    for k, axis in enumerate(AXES):  # per axis, as the paper's Fig. 16
        axes[1].plot(*envelope(t, series["edot_true"][:, k], width), label=f"ė_{axis.lower()}")
    axes[1].set_ylabel("ė [m/s]")
    for k in range(series["tau"].shape[1]):
        (line,) = axes[2].plot(*envelope(t, series["tau"][:, k], width))
        t_pk, val = peak_of(t, series["tau"][:, k])
        mark_peak(axes[2], t_pk, val, color=line.get_color())
        line.set_label(peak_label(f"τ{k + 1}: ", t_pk, val, "N·m"))
    axes[2].set_ylabel("torque [N·m]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        _mark_times(ax, tfs)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    place_grid(fig, axes, fig.suptitle(f"{title}: interception error, velocity error, torques"))
    save(fig, out_dir, "errors", formats, laid_out=True)


def _joints_figure(series: dict, metrics: dict, tfs, out_dir: Path, title: str, formats) -> None:
    t = series["t"]
    fig = new_figure((8, 7))
    axes = fig.subplots(series["q"].shape[1], 1, sharex=True)
    for k, ax in enumerate(np.atleast_1d(axes)):
        ax.plot(*envelope(t, np.degrees(series["q"][:, k]), _columns(fig)))
        ax.set_ylabel(f"θ{k + 1} [deg]")
        _mark_times(ax, tfs)
        ax.grid(alpha=0.3)
    np.atleast_1d(axes)[0].legend(fontsize=8, loc="best")
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    place_grid(fig, axes, fig.suptitle(f"{title}: joint trajectories (model angles θ)"))
    save(fig, out_dir, "joints", formats, laid_out=True)


def _paths_figure(series: dict, metrics: dict, tfs, out_dir: Path, title: str, formats) -> None:
    t = series["t"]
    fig = new_figure((7.5, 6.5), layout="constrained")
    ax = fig.add_subplot(projection="3d")
    ax.plot(*series["x"].T, label="robot")
    objects = series["objects"].reshape(len(t), -1, 3)
    for i in range(objects.shape[1]):
        ax.plot(*objects[:, i, :].T, "--", label=f"target {i + 1}" if objects.shape[1] > 1 else "target")
    for s, tf in zip(metrics["segments"], tfs):
        k = min(np.searchsorted(t, tf), len(t) - 1)
        ax.scatter(*series["x"][k], color="r", s=30)
    ax.scatter(*series["x"][0], color="k", s=20, label="start")
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_zlabel("Z [m]")
    ax.scatter([], [], color="r", s=30, label="robot at $t_f$")
    fig.legend(fontsize=8, loc="outside lower center", ncol=6)
    fig.suptitle(f"{title}: 3D paths, red dots at the prescribed times")
    save(fig, out_dir, "paths3d", formats)


def _angle_figure(series: dict, metrics: dict, tfs, out_dir: Path, title: str, formats) -> None:
    """The orientation error angle per object (deg, log axis) from its segment's start to the end
    of its hold, the angle at tf circled, the criteria and tf marked (tasks pose and top_down)."""
    t, angle = series["t"], series["rot_angle_deg"]
    fig = new_figure((10, 4.2), layout="constrained")
    ax = fig.subplots()
    width = _columns(fig)
    for i in range(angle.shape[1]):
        seen = np.isfinite(angle[:, i])
        ax.semilogy(*envelope(t[seen], np.maximum(angle[seen, i], 1e-6), width), label=f"object {i}")
    criteria = metrics.get("criteria", {})
    bound, hold = criteria.get("e_rot_tf_deg", 2.0), criteria.get("rot_hold_deg", 5.0)
    ax.axhline(bound, color="r", lw=0.8, label=f"{bound:g}° at $t_f$")
    ax.axhline(hold, color="r", ls=":", lw=0.8, label=f"{hold:g}° holding")
    at_tf = [(tf, max(s["e_rot_tf_deg"], 1e-6)) for tf, s in zip(tfs, metrics["segments"])
             if s.get("e_rot_tf_deg") is not None]
    if at_tf:
        ax.plot(*zip(*at_tf), ls="none", marker="o", mfc="none", color="k", ms=7, label="angle at $t_f$")
    values = ", ".join("n/a" if s.get("e_rot_tf_deg") is None else f"{s['e_rot_tf_deg']:.3g}"
                       for s in metrics["segments"])
    ax.set_title(f"angle($t_f$) = {values}° (criterion ≤ {bound:g}°)", fontsize=10)
    _mark_times(ax, tfs)
    ax.grid(alpha=0.3)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("orientation error [deg]")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(f"{title}: angle between the gripper's orientation and the one its task asks for")
    save(fig, out_dir, "angle", formats)


RUN_FIGURES = {"axes": _axes_figure, "errors": _errors_figure, "joints": _joints_figure,
               "paths3d": _paths_figure}
# a task with orientation (controller.task pose or top_down) adds these
ORIENTATION_FIGURES = {"angle": _angle_figure}


def run_figure_stems(task: str) -> list[str]:
    """The figures of a run whose controller has ``task``: ``RUN_FIGURES``, and
    ``ORIENTATION_FIGURES`` unless the task is position."""
    return list(RUN_FIGURES) + ([] if task == "position" else list(ORIENTATION_FIGURES))
