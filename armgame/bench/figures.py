"""The work-precision and convergence figures (matplotlib, the optional ``plot``/``bench`` extra)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

from ..errors import UserError
from ..physics.integrators import SCHEMES
from ..records.storage import save_figure
from .measure import Row

FLOOR = 1e-13  # errors below this are round-off; drawn at the floor so log axes keep them


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise UserError("figures need matplotlib: pip install 'armgame[bench]' (or run without --out)") from None
    return plt


def _usable(r: Row) -> bool:
    return not r.blew_up and math.isfinite(r.hand_error) and math.isfinite(r.time_per_sim_s)


def work_precision(rows: Sequence[Row], path: Path) -> None:
    """Hand error against wall time per simulated second, one panel per case, one line per method."""
    plt = _pyplot()
    cases = list(dict.fromkeys(r.case for r in rows))
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 4.2), squeeze=False)
    methods = list(dict.fromkeys(r.method for r in rows))
    for ax, case in zip(axes[0], cases, strict=True):
        for method in methods:
            pts = sorted((r.time_per_sim_s, max(r.hand_error, FLOOR)) for r in rows
                         if r.case == case and r.method == method and _usable(r))
            if pts:
                style = "-o" if any(r.family == "armgame" for r in rows if r.method == method) else "--s"
                ax.loglog([p[0] * 1e3 for p in pts], [p[1] for p in pts], style, ms=3, label=method)
        ax.axhline(1e-4, color="grey", lw=0.6, ls=":")
        ax.set_title(case)
        ax.set_xlabel("ms of wall time per simulated s")
        ax.grid(True, which="major", alpha=0.3)
    axes[0][0].set_ylabel("largest hand error over 2 s (m)")
    axes[0][-1].legend(fontsize=7, loc="best")
    fig.suptitle("Work-precision: one arm, as the game steps it (dotted: 0.1 mm)")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def convergence(rows: Sequence[Row], path: Path) -> None:
    """Hand error against step size for the fixed-step methods, with slopes 1, 2 and 4."""
    plt = _pyplot()
    fixed = [r for r in rows if r.dt is not None]
    cases = list(dict.fromkeys(r.case for r in fixed))
    if not cases:
        return
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 4.2), squeeze=False)
    methods = list(dict.fromkeys(r.method for r in fixed))
    for ax, case in zip(axes[0], cases, strict=True):
        for method in methods:
            pts = sorted((r.dt, max(r.hand_error, FLOOR)) for r in fixed
                         if r.case == case and r.method == method and _usable(r))
            if pts:
                ax.loglog([p[0] for p in pts], [p[1] for p in pts], "-o", ms=3, label=method)
        dts = sorted({r.dt for r in fixed})
        lo, hi = dts[0], dts[-1]
        for order in sorted({s.order for s in SCHEMES.values()}):
            anchor = 1e-2
            ax.loglog([lo, hi], [anchor * (lo / hi) ** order, anchor], color="grey", lw=0.6, ls=":")
            ax.text(hi, anchor, f" slope {order}", fontsize=7, color="grey", va="center")
        ax.set_title(case)
        ax.set_xlabel("step dt (s)")
        ax.grid(True, which="major", alpha=0.3)
    axes[0][0].set_ylabel("largest hand error over 2 s (m)")
    axes[0][-1].legend(fontsize=7, loc="best")
    fig.suptitle("Convergence: error against step, reference slopes 1, 2, 4")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)
