"""Issue 41's figures: the frames test, generalization probed without vision, and the two new fits.

Drawn as the lab's other figures are (``armgame.lab.figures``: matplotlib's ``Figure``, 1920 x 1080, the lab's font
sizes, written atomically), each a picture a student puts in a write-up:

* ``frames.png``: each channel trial of a frames test, its index against the field held at the hand and held at
  the joints, less each direction's baseline at that posture;
* ``generalization.png``: the fraction of a trained rotation each probed direction shows, by angle;
* a trial-by-trial fit's generalization function ``c(delta)`` with its intervals, and a state-space fit over its
  data.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .figures import (
    CATCH,
    LINE,
    _figure,
    _fit_axes,
    _lab_style,
    _legend_below,
    _save,
)


@_lab_style
def frames_figure(table: Sequence[Mapping[str, Any]], path: Path, caption: str) -> None:
    """``table``: per channel trial of the test (``trial``, ``hand``, ``joint``), indices less their baselines."""
    fig = _figure()
    ax = fig.add_subplot()
    trial = np.array([r["trial"] for r in table], dtype=float)
    ax.plot(trial, [r["hand"] for r in table], "o-", color=LINE, ms=9, lw=1.5, label="field held at the hand")
    ax.plot(trial, [r["joint"] for r in table], "s-", color=CATCH, ms=9, lw=1.5, label="field held at the joints")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.axhline(1.0, color="#888888", lw=1.0, ls="--")
    ax.set_xlabel("trial")
    ax.set_ylabel("adaptation index at the test posture")
    ax.grid(alpha=0.3, axis="y")
    ax.set_title(f"Which frame was the field learned in? {caption}")
    _legend_below(fig, ax)
    _save(fig, path)


@_lab_style
def rotation_generalization_figure(table: Sequence[Mapping[str, Any]], path: Path, caption: str) -> None:
    """``probe_generalization``'s table: the fraction of the rotation shown by angle from the trained direction."""
    fig = _figure()
    ax = fig.add_subplot()
    angle = np.array([r["angle_deg"] for r in table], dtype=float)
    value = np.array([r["generalization"] for r in table], dtype=float)
    ax.plot(angle, value, "o-", color=LINE, ms=11, lw=2.0, label="probes without vision")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.axhline(1.0, color="#888888", lw=1.0, ls="--", label="the whole rotation")
    ax.set_xticks(angle)
    ax.set_xlabel("angle of the probed direction from the trained one (deg)")
    ax.set_ylabel("fraction of the rotation expressed")
    ax.grid(alpha=0.3)
    ax.set_title(f"Generalization of a visuomotor rotation: {caption}")
    _legend_below(fig, ax)
    _save(fig, path)


@_lab_style
def generalization_fit_figure(fit: Any, path: Path, unit: str = "", scale: float = 1.0) -> None:
    """A trial-by-trial fit (``trialfit.GeneralizationFit``): ``c(delta)`` with its 95% intervals, both signs of
    the angle drawn (the function is symmetric)."""
    fig = _figure()
    ax = fig.add_subplot()
    angles = [a for a in fit.angles_deg]
    shown = sorted({-a for a in angles if 0 < a < 180} | set(angles))
    value = [fit.values[f"c({abs(a):g})"] for a in shown]
    low = [fit.intervals[f"c({abs(a):g})"][0] for a in shown]
    high = [fit.intervals[f"c({abs(a):g})"][1] for a in shown]
    ax.errorbar(shown, value, yerr=[np.subtract(value, low), np.subtract(high, value)], fmt="o-", color=LINE, ms=10,
                lw=2.0, capsize=6, label="c(delta), 95% profile-likelihood interval")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.set_xticks(shown)
    ax.set_xlabel("angle between the reach and the one before it that erred (deg)")
    ax.set_ylabel("fraction of the error corrected")
    ax.grid(alpha=0.3)
    per = f" {unit}" if unit else ""
    ax.set_title(f"Generalization function from trial-to-trial changes: a {fit.values['a']:.3g}, "
                 f"k {scale * fit.values['k']:.3g}{per}")
    _legend_below(fig, ax)
    _save(fig, path)


@_lab_style
def state_space_figure(rows: Sequence[Mapping[str, Any]], fit: Any, path: Path, metric: str) -> None:
    """A state-space fit over its data: the observations and the smoothed state's prediction, blocks shaded."""
    fig, ax, trial, label, scale = _fit_axes(rows, metric)
    y = np.array([float(r[metric]) for r in rows]) * scale
    ax.plot(trial, y, "o", color=LINE, ms=4, label="data")
    if fit.observed_kind == "error":
        f = np.array([float(r["disturbance"]) for r in rows])
        predicted = fit.values["k"] * (np.where(np.isfinite(f), f, 0.0) - fit.estimate) * scale
    else:
        predicted = fit.estimate * scale
    ax.plot(trial, predicted, "-", color=CATCH, lw=2.0, label="state (Kalman smoother), as the data would read it")
    ax.axhline(0.0, color="black", lw=1.0)
    ax.set_xlabel("trial")
    ax.set_ylabel(label)
    ax.grid(alpha=0.3, axis="y")
    v = fit.values
    ax.set_title(f"State-space fit: A {v['A']:.4g}, B {v['B']:.3g}, process s.d. {math.sqrt(v['Q']):.3g} (field), "
                 f"output s.d. {scale * math.sqrt(v['R']):.3g}")
    _legend_below(fig, ax)
    _save(fig, path)


def design_figures(session: Any, rows: Sequence[Mapping[str, Any]], out: Path) -> list[Path]:
    """The figures of issue 41's designs a run has: ``frames.png`` for a frames test, ``generalization.png`` for a
    rotation's generalization probed by catch trials. What was written."""
    from .designs import frames_table, probe_generalization

    written = []
    caption = f"{session.protocol.name}, seed {session.config.seed}"
    table = frames_table(session, rows)
    if table:
        frames_figure(table, out / "frames.png", caption)
        written.append(out / "frames.png")
    probes = probe_generalization(session, rows)
    if probes:
        rotation_generalization_figure(probes, out / "generalization.png", caption)
        written.append(out / "generalization.png")
    return written
