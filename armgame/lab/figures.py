"""The lab's figures: a learning curve, hand paths by phase, and a class's mean curve.

Drawn with matplotlib (the optional ``plot`` extra), imported only when a figure is drawn, on
``matplotlib.figure.Figure`` rather than pyplot so that no GUI backend or global state is touched.
Every figure is 16:9 and 1920 x 1080 pixels, with text of at least 12 pt, so that it reads on a
projector; legends sit outside the data. PNGs are written atomically through
``armgame.records.storage`` and only over a regular file.

``class_curve`` is pure Python and numpy: it needs no matplotlib.
"""

from __future__ import annotations

import functools
import io
import itertools
import math
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any, ParamSpec

import numpy as np

from ..errors import UserError
from ..records.storage import atomic_write_bytes
from ..words import unknown_name
from .metrics import METRIC_COLUMNS, check_regular_target

P = ParamSpec("P")
WIDTH, HEIGHT, DPI = 16.0, 9.0, 120  # 1920 x 1080 px
FONT = {"font.size": 15, "axes.titlesize": 18, "axes.labelsize": 16, "xtick.labelsize": 14,
        "ytick.labelsize": 14, "legend.fontsize": 14, "figure.titlesize": 20}

#: How each measure is labelled, and the factor from its stored unit to the unit shown.
MEASURES: dict[str, tuple[str, float]] = {
    "initial_direction_error_deg": ("initial direction error (deg, + = counter-clockwise)", 1.0),
    "max_perpendicular_error_m": ("maximum perpendicular error (cm, + = left)", 100.0),
    "path_length_ratio": ("path length / straight distance", 1.0),
    "peak_speed_m_per_s": ("peak speed (m/s)", 1.0),
    "reaction_time_s": ("reaction time (ms)", 1000.0),
    "movement_time_s": ("movement time (ms)", 1000.0),
}
assert set(MEASURES) == set(METRIC_COLUMNS)

# Block shading by what the block does: unperturbed blocks grey, perturbed ones warm; repeats alternate.
UNPERTURBED_SHADES = ("#e8e8e8", "#d6e4f0")
PERTURBED_SHADES = ("#fde2c4", "#f7d0d0", "#e6d8f0")
LINE, CATCH, MISS = "#1f3b57", "#c0392b", "#7f8c8d"


def require_matplotlib() -> None:
    """Raise a one-line ``UserError`` unless matplotlib can be imported."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError("lab figures need matplotlib: pip install 'armgame[plot]'") from None


def _figure(layout: str | None = "constrained") -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(WIDTH, HEIGHT), dpi=DPI, layout=layout)


def _lab_style(draw: Callable[P, None]) -> Callable[P, None]:
    """Draw under the lab's font sizes: rc settings are read as artists are made and ticks drawn,
    so the whole figure, saving included, runs inside one ``rc_context`` (restored afterwards)."""

    @functools.wraps(draw)
    def styled(*args: P.args, **kwargs: P.kwargs) -> None:
        require_matplotlib()
        from matplotlib import rc_context

        with rc_context(FONT):
            draw(*args, **kwargs)
    return styled


# ------------------------------------------------------------------------------------ pure helpers

def blocks_of(rows: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    """Contiguous runs of one block label, in order: name, first and last trial, and its perturbation.

    A block's perturbation is the one most of its trials had; trials that differ from it are its
    catch trials (the field switched off, or on, without warning).
    """
    spans: list[dict[str, Any]] = []
    for row in rows:
        if spans and spans[-1]["block"] == row["block"]:
            spans[-1]["rows"].append(row)
        else:
            spans.append({"block": row["block"], "rows": [row]})
    for span in spans:
        counts = Counter(str(r["perturbation"]) for r in span["rows"])
        span["perturbation"] = max(counts, key=lambda name: (counts[name], -_first(span["rows"], name)))
        span["first"], span["last"] = span["rows"][0]["trial"], span["rows"][-1]["trial"]
        span["catch"] = [r["trial"] for r in span["rows"] if str(r["perturbation"]) != span["perturbation"]]
    return spans


def _first(rows: Sequence[Mapping[str, Any]], perturbation: str) -> int:
    return next(i for i, r in enumerate(rows) if str(r["perturbation"]) == perturbation)


def class_curve(students: Sequence[Sequence[Mapping[str, Any]]],
                metric: str = "initial_direction_error_deg") -> list[dict[str, Any]]:
    """The class's mean learning curve: per trial number, the mean and s.e.m. over students.

    ``students``: one sequence of trial rows (``TRIAL_COLUMNS``) per student. Trials are matched by
    their ``trial`` number, so students who ran different numbers of trials (a run stopped early, a
    longer protocol) each count where they have data: ``n`` is the number of students with a defined
    (finite) ``metric`` on that trial, a reach whose hand was sent home (``hand_sent_home``) not counted.
    ``mean`` is NaN where ``n`` = 0; ``sem`` is the sample
    standard deviation over the square root of ``n`` and NaN where ``n`` < 2. ``block`` and
    ``perturbation`` are those most students had on that trial. Returns one dict per trial number
    seen, in order: ``trial, block, perturbation, mean, sem, n``.
    """
    if metric not in METRIC_COLUMNS:
        raise UserError(unknown_name("measure", metric, METRIC_COLUMNS))
    values: dict[int, list[float]] = {}
    labels: dict[int, Counter] = {}
    for s, rows in enumerate(students, start=1):
        seen: set[int] = set()
        for row in rows:
            trial = int(row["trial"])
            if trial in seen:
                raise UserError(f"student {s} has trial {trial} twice")
            seen.add(trial)
            labels.setdefault(trial, Counter())[(str(row["block"]), str(row["perturbation"]))] += 1
            # A reach abandoned with space (the hand sent home) is not one of the experiment's: no value here.
            value = math.nan if row.get("hand_sent_home") else float(row[metric])
            values.setdefault(trial, [])
            if math.isfinite(value):
                values[trial].append(value)
    curve = []
    for trial in sorted(values):
        data = np.array(values[trial])
        n = data.size
        block, perturbation = labels[trial].most_common(1)[0][0]
        curve.append({
            "trial": trial, "block": block, "perturbation": perturbation,
            "mean": float(data.mean()) if n else math.nan,
            "sem": float(data.std(ddof=1) / math.sqrt(n)) if n > 1 else math.nan,
            "n": n,
        })
    return curve


# --------------------------------------------------------------------------------------- figures

@_lab_style
def learning_figure(rows: Sequence[Mapping[str, Any]], path: Path,
                    metric: str = "initial_direction_error_deg") -> None:
    """One measure trial by trial: blocks shaded and named, catch trials and misses marked.

    The first trials of an unperturbed block that follows a perturbed one are labelled
    "after-effect": there the error flips sign when an internal model of the field was learned.
    Trials are placed by their ``trial`` number, or in row order when the numbers do not increase.
    """
    label, scale = _measure(metric)
    if not rows:
        raise UserError("no trials to draw")
    numbers = [r["trial"] for r in rows]
    if any(b <= a for a, b in itertools.pairwise(numbers)):  # numbered per block, or merged runs: plot in order
        rows = [{**r, "trial": n} for n, r in enumerate(rows, start=1)]
    fig = _figure()
    ax = fig.add_subplot()
    spans = blocks_of(rows)
    _shade_blocks(ax, spans)

    catch = {t for span in spans for t in span["catch"]}
    for span in spans:
        trials = np.array([r["trial"] for r in span["rows"] if r["trial"] not in catch], dtype=float)
        y = np.array([float(r[metric]) * scale for r in span["rows"] if r["trial"] not in catch])
        ax.plot(trials, y, "-", color=LINE, lw=1.2, alpha=0.6)
    trial = np.array([r["trial"] for r in rows], dtype=float)
    y = np.array([float(r[metric]) * scale for r in rows])
    hit = np.array([bool(r["hit"]) for r in rows])
    is_catch = np.isin(trial, list(catch))
    normal = ~is_catch
    ms = _marker_size(len(rows))
    ax.plot(trial[normal & hit], y[normal & hit], "o", color=LINE, ms=ms, label="reach, target hit")
    if (normal & ~hit).any():
        ax.plot(trial[normal & ~hit], y[normal & ~hit], "o", mfc="white", mec=MISS, mew=1.5, ms=ms,
                label="reach, target missed")
    channel = np.array([r["perturbation"] == "channel" for r in rows])
    if (is_catch & ~channel).any():
        ax.plot(trial[is_catch & ~channel], y[is_catch & ~channel], "D", color=CATCH, ms=max(8.0, ms * 1.5),
                label="catch trial")
    if (is_catch & channel).any():  # held on the line: their error is ~0 by construction
        ax.plot(trial[is_catch & channel], y[is_catch & channel], "s", mfc="white", mec=CATCH, mew=1.5,
                ms=max(8.0, ms * 1.5), label="error-clamp (channel) trial")
    _after_effect(ax, spans, metric, scale)

    ax.axhline(0.0, color="black", lw=1.0)
    ax.set_xlabel("trial")
    ax.set_ylabel(label)
    ax.set_xlim(trial.min() - 0.5, trial.max() + 0.5)
    _headroom(ax, y)
    ax.grid(alpha=0.3, axis="y")
    ax.set_title(f"Learning curve: {label.split(' (')[0]}, trial by trial")
    _legend_below(fig, ax)
    _save(fig, path)


@_lab_style
def paths_figure(groups: Mapping[str, Sequence[np.ndarray]], home: Sequence[float],
                 targets: Sequence[Sequence[float]], path: Path, *, target_radius: float | None = None,
                 caption: str | None = None) -> None:
    """Hand paths side by side, one panel per group, as in Shadmehr & Mussa-Ivaldi (1994).

    ``groups`` maps a panel title (for example "baseline", "early exposure", "late exposure", "early
    washout") to that phase's hand paths, each an (n, 2) array in metres. Paths are drawn relative to
    ``home`` in centimetres, with the home position and the ``targets`` (circles of
    ``target_radius`` m, or markers) in every panel, on one scale with equal aspect. ``caption``: a
    line or two under the panels saying what to look for.
    """
    if not groups:
        raise UserError("no hand paths to draw")
    home_xy = np.asarray(home, dtype=float)
    target_xy = (np.asarray(targets, dtype=float).reshape(-1, 2) - home_xy) * 100.0
    drawn = {name: [(np.asarray(p, dtype=float).reshape(-1, 2) - home_xy) * 100.0 for p in paths]
             for name, paths in groups.items()}
    every = [target_xy, np.zeros((1, 2))] + [p[np.isfinite(p).all(axis=1)] for ps in drawn.values() for p in ps]
    points = np.vstack(every)
    pad = max(1.5, (target_radius or 0.0) * 100.0 * 1.5)
    low, high = points.min(axis=0) - pad, points.max(axis=0) + pad
    centre, half = (low + high) / 2.0, max(high - low) / 2.0

    # Square panels side by side leave spare height on a 16:9 page; placing them by hand keeps the
    # title and the caption next to the panels instead of at the page's edges.
    fig = _figure(layout=None)
    k, gap, left, right = len(drawn), 0.012, 0.06, 0.99
    w = (right - left - (k - 1) * gap) / k
    h = min(w * WIDTH / HEIGHT, 0.62)
    w = h * HEIGHT / WIDTH
    x0 = left + (right - left - k * w - (k - 1) * gap) / 2.0
    middle = 0.53
    axes = [fig.add_axes((x0 + i * (w + gap), middle - h / 2.0, w, h)) for i in range(k)]
    for ax in axes[1:]:
        ax.sharex(axes[0])
        ax.sharey(axes[0])
        ax.tick_params(labelleft=False)
    from matplotlib.patches import Circle

    for ax, (name, paths) in zip(axes, drawn.items(), strict=True):
        for tx, ty in target_xy:
            if target_radius:
                ax.add_patch(Circle((tx, ty), target_radius * 100.0, fc="#f5b7b1", ec=CATCH, lw=1.0, zorder=1))
            else:
                ax.plot(tx, ty, "o", ms=12, mfc="#f5b7b1", mec=CATCH, zorder=1)
        for p in paths:
            ax.plot(p[:, 0], p[:, 1], color=LINE, lw=1.6, alpha=0.85, zorder=2)
        ax.plot(0.0, 0.0, "o", ms=10, mfc="white", mec="black", mew=2.0, zorder=3)
        ax.set_title(f"{name}\n({len(paths)} reach{'' if len(paths) == 1 else 'es'})")
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_xlabel("x from home (cm)")
        ax.grid(alpha=0.25)
    axes[0].set_ylabel("y from home (cm)")
    fig.suptitle("Hand paths (home: open circle; targets: red)", y=middle + h / 2.0 + 0.10, va="bottom")
    if caption:
        fig.text(0.5, middle - h / 2.0 - 0.11, caption, ha="center", va="top", fontsize=16, color="#333333")
    _save(fig, path)


@_lab_style
def class_figure(curve: Sequence[Mapping[str, Any]], path: Path, *,
                 metric: str = "initial_direction_error_deg") -> None:
    """The class curve from ``class_curve``: the mean with its s.e.m. band, blocks shaded, n below."""
    _draw_class(curve, metric, lambda fig: _save(fig, path))


def class_figure_png(curve: Sequence[Mapping[str, Any]], *, metric: str = "initial_direction_error_deg") -> bytes:
    """``class_figure``'s picture as PNG bytes (the class's teacher page downloads it); UserError without
    matplotlib."""
    drawn: list[bytes] = []
    _class_png(curve, drawn, metric=metric)
    return drawn[0]


@_lab_style
def _class_png(curve: Sequence[Mapping[str, Any]], drawn: list[bytes], *, metric: str) -> None:
    def keep(fig: Any) -> None:
        buffer = io.BytesIO()
        fig.savefig(buffer, format="png")
        drawn.append(buffer.getvalue())
    _draw_class(curve, metric, keep)


def _draw_class(curve: Sequence[Mapping[str, Any]], metric: str, finish: Callable[[Any], None]) -> None:
    label, scale = _measure(metric)
    if not curve:
        raise UserError("no trials to draw")
    fig = _figure()
    n = np.array([c["n"] for c in curve])
    varies = n.min() != n.max()
    if varies:
        ax, n_ax = fig.subplots(2, 1, sharex=True, height_ratios=(4, 1))
    else:
        ax, n_ax = fig.add_subplot(), None
    spans = blocks_of(curve)
    _shade_blocks(ax, spans)
    trial = np.array([c["trial"] for c in curve], dtype=float)
    mean = np.array([c["mean"] for c in curve]) * scale
    sem = np.array([c["sem"] for c in curve]) * scale
    band = np.where(np.isfinite(sem), sem, 0.0)
    catch = np.isin(trial, [t for span in spans for t in span["catch"]])
    for span in spans:  # one line per block, broken at catch trials as in the single-run figure
        inside = (trial >= span["first"]) & (trial <= span["last"]) & ~catch
        ax.fill_between(trial[inside], mean[inside] - band[inside], mean[inside] + band[inside], color=LINE,
                        alpha=0.25, lw=0, label="± 1 s.e.m." if span is spans[0] else None)
        ax.plot(trial[inside], mean[inside], "-o", color=LINE, ms=_marker_size(len(curve)) * 0.7, lw=1.5,
                label="class mean" if span is spans[0] else None)
    if catch.any():
        ax.errorbar(trial[catch], mean[catch], yerr=band[catch], fmt="D", color=CATCH,
                    ms=max(8.0, _marker_size(len(curve)) * 1.5), label="catch trial")
    _after_effect(ax, spans, "mean", scale)
    ax.axhline(0.0, color="black", lw=1.0)
    ax.set_ylabel(label)
    ax.set_xlim(trial.min() - 0.5, trial.max() + 0.5)
    _headroom(ax, np.concatenate([mean - band, mean + band]))
    ax.grid(alpha=0.3, axis="y")
    students = int(n.max())
    ax.set_title(f"Class learning curve: mean ± s.e.m. over {students} student{'' if students == 1 else 's'}")
    if n_ax is not None:
        n_ax.step(trial, n, where="mid", color="black")
        n_ax.set_ylabel("students")
        n_ax.set_ylim(0, students + 0.5)
        n_ax.set_xlabel("trial")
        n_ax.grid(alpha=0.3, axis="y")
    else:
        ax.set_xlabel("trial")
    _legend_below(fig, n_ax if n_ax is not None else ax, handles_from=ax)
    finish(fig)


# ------------------------------------------------------------------------------------- internals

def _measure(metric: str) -> tuple[str, float]:
    if metric not in MEASURES:
        raise UserError(unknown_name("measure", metric, MEASURES))
    return MEASURES[metric]


def _marker_size(trials: int) -> float:
    """Points that stay apart: 6 pt up to 100 trials, then smaller, down to 2.5 pt (about 400 trials)."""
    return max(2.5, min(6.0, 600.0 / max(trials, 1)))


def _shade_blocks(ax: Any, spans: list[dict[str, Any]]) -> None:
    unperturbed = spans[0]["perturbation"]
    shown: Counter = Counter()
    for span in spans:
        plain = span["perturbation"] == unperturbed
        shades = UNPERTURBED_SHADES if plain else PERTURBED_SHADES
        colour = shades[shown[plain] % len(shades)]
        shown[plain] += 1
        ax.axvspan(span["first"] - 0.5, span["last"] + 0.5, color=colour, lw=0, zorder=0)
        name = span["block"] if span["perturbation"] in (span["block"], unperturbed) or plain \
            else f"{span['block']}\n({span['perturbation']})"
        ax.text((span["first"] + span["last"]) / 2.0, 0.98, name, transform=ax.get_xaxis_transform(),
                ha="center", va="top", fontsize=15, fontweight="bold", color="#333333")


def _after_effect(ax: Any, spans: list[dict[str, Any]], key: str, scale: float) -> None:
    unperturbed = spans[0]["perturbation"]
    for before, span in itertools.pairwise(spans):
        if before["perturbation"] == unperturbed or span["perturbation"] != unperturbed:
            continue
        first = next(((r["trial"], float(r[key]) * scale) for r in span["rows"]
                      if math.isfinite(float(r[key])) and r["trial"] not in span["catch"]), None)
        if first is None:
            continue
        # To the left, at the point's height: the perturbed block's errors lie on the other side of
        # zero there, so the label sits in empty space rather than on the washout's own points.
        ax.annotate("after-effect", xy=first, xytext=(-30, 0), textcoords="offset points", ha="right",
                    va="center", fontsize=15, color=CATCH, fontweight="bold",
                    arrowprops={"arrowstyle": "->", "color": CATCH, "lw": 1.5})


def _headroom(ax: Any, y: np.ndarray) -> None:
    """Room at the top for the block names, and zero always in view."""
    finite = y[np.isfinite(y)]
    low, high = (min(finite.min(), 0.0), max(finite.max(), 0.0)) if finite.size else (-1.0, 1.0)
    span = (high - low) or 1.0
    ax.set_ylim(low - 0.08 * span, high + 0.22 * span)


def _legend_below(fig: Any, ax: Any, handles_from: Any = None) -> None:
    handles, labels = (handles_from or ax).get_legend_handles_labels()
    if handles:
        legend = fig.legend(handles, labels, loc="outside lower center", ncols=len(handles), frameon=False)
        for handle in legend.legend_handles:  # one legible size, however small the plotted points
            if hasattr(handle, "set_markersize"):
                handle.set_markersize(9)


def _save(fig: Any, path: Path) -> None:
    path = Path(path)
    check_regular_target(path)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png")
    try:
        atomic_write_bytes(path, buffer.getvalue())
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None


def _fit_axes(rows: Sequence[Mapping[str, Any]], metric: str) -> tuple[Any, Any, np.ndarray, str, float]:
    """A fit figure's frame: the figure, its axes with the blocks shaded, the trials' numbers, and the metric's
    axis label and scale (``adaptation_index``: the channel trials' index, as it is)."""
    label, scale = ("adaptation index (channel trials)", 1.0) if metric == "adaptation_index" else _measure(metric)
    rows = [{**r, "trial": n} for n, r in enumerate(rows, start=1)]
    fig = _figure()
    ax = fig.add_subplot()
    _shade_blocks(ax, blocks_of(rows))
    return fig, ax, np.arange(1, len(rows) + 1, dtype=float), label, scale


@_lab_style
def fit_figure(rows: Sequence[Mapping[str, Any]], fit: Any, path: Path, metric: str, other: Any = None) -> None:
    """A learner's fit (``armgame.lab.fit.LearnerFit``) drawn over the data it was fitted to, blocks shaded,
    the parameters in the title; ``metric`` the fitted column (``adaptation_index`` for indices); ``other``, a
    second model's fit to the same data, dashed beside it."""
    fig, ax, trial, label, scale = _fit_axes(rows, metric)
    seen = np.isfinite(fit.observed)
    ax.plot(trial[seen], fit.observed[seen] * scale, "o", color=LINE, ms=_marker_size(len(rows)), label="data")
    shown = np.isfinite(fit.predicted) & (seen | (fit.observed_kind == "index"))
    ax.plot(trial[shown], fit.predicted[shown] * scale, "-", color=CATCH, lw=2.0,
            label=f"{fit.model} fit (AIC {fit.aic:.1f})" if other is not None else f"{fit.model} fit")
    if other is not None:
        ax.plot(trial[shown], other.predicted[shown] * scale, "--", color=LINE, lw=1.5,
                label=f"{other.model} fit (AIC {other.aic:.1f})")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.set_xlabel("trial")
    ax.set_ylabel(label)
    ax.set_xlim(0.5, len(rows) + 0.5)
    _headroom(ax, np.concatenate([fit.observed[seen], fit.predicted[shown]]) * scale)
    ax.grid(alpha=0.3, axis="y")
    v = fit.values
    rates = (f"A_f {v['retention_fast']:.3g}, A_s {v['retention_slow']:.4g}, B_f {v['rate_fast']:.3g}, "
             f"B_s {v['rate_slow']:.3g}" if "rate_fast" in v else f"A {v['retention']:.4g}, B {v['rate']:.3g}")
    ax.set_title(f"{fit.model.capitalize()} fit: {rates}; rms residual {fit.rms * scale:.3g}, R² {fit.r_squared:.2f}")
    _legend_below(fig, ax)
    _save(fig, path)


@_lab_style
def adaptation_figure(rows: Sequence[Mapping[str, Any]], path: Path) -> None:
    """The adaptation index of the error-clamp (channel) trials, trial by trial, blocks shaded: what the
    channel measured, learning without the error that taught it (0 nothing learned, 1 the field cancelled)."""
    rows = [{**r, "trial": n} for n, r in enumerate(rows, start=1)]
    points = [(r["trial"], float(r["adaptation_index"])) for r in rows
              if r["perturbation"] == "channel" and math.isfinite(float(r["adaptation_index"]))]
    if not points:
        raise UserError("no channel trial with an adaptation index to draw")
    fig = _figure()
    ax = fig.add_subplot()
    _shade_blocks(ax, blocks_of(rows))
    trial, index = (np.array(v, dtype=float) for v in zip(*points, strict=True))
    ax.plot(trial, index, "s", mfc="white", mec=CATCH, mew=1.5, ms=max(6.0, _marker_size(len(rows)) * 1.3),
            label="channel trial")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.axhline(1.0, color=LINE, lw=1.0, ls="--", label="field fully compensated")
    ax.set_xlabel("trial")
    ax.set_ylabel("adaptation index")
    ax.set_xlim(0.5, len(rows) + 0.5)
    _headroom(ax, np.concatenate([index, [0.0, 1.0]]))
    ax.grid(alpha=0.3, axis="y")
    ax.set_title("Adaptation index of the error-clamp trials")
    _legend_below(fig, ax)
    _save(fig, path)
