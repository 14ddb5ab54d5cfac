"""The work-precision and convergence figures (matplotlib, the optional ``plot``/``bench`` extra).

Each is one 16:9 slide (``armgame.plotstyle``): one panel per case in a grid of up to three
columns, and the legend in a cell of its own, off the data. A method keeps its colour and marker
in every panel: armgame's schemes solid with circles, the peers dashed with squares.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..plotstyle import require_matplotlib, save, slide_figure, slide_style
from .measure import Row

FLOOR = 1e-13  # errors below this are round-off; drawn at the floor so log axes keep them
ERROR_LABEL = "largest hand error over 2 s (m)"
SLOPE_STYLES = {1: {"color": "#888888", "lw": 1.5, "ls": ":"}, 2: {"color": "#888888", "lw": 1.5, "ls": "-."},
                4: {"color": "#555555", "lw": 1.5, "ls": (0, (6, 3))}}


def require() -> None:
    require_matplotlib("bench", "run without --out")


def _usable(r: Row) -> bool:
    return not r.blew_up and math.isfinite(r.hand_error) and math.isfinite(r.time_per_sim_s)


def _grid(fig: Any, panels: int) -> tuple[list[Any], Any]:
    """Axes for ``panels`` cases plus one cell for the legend, up to three columns."""
    cols = min(3, panels + 1)
    rows = math.ceil((panels + 1) / cols)
    cells = fig.subplots(rows, cols, squeeze=False).ravel()
    for spare in cells[panels + 1:]:
        spare.remove()
    legend_cell = cells[panels]
    legend_cell.axis("off")
    return list(cells[:panels]), legend_cell


def _styles(rows: Sequence[Row]) -> dict[str, dict[str, Any]]:
    from matplotlib import colormaps

    colours = colormaps["tab10"].colors
    methods = list(dict.fromkeys(r.method for r in rows))
    ours = {r.method for r in rows if r.family in ("armgame", "compiled")}
    return {m: {"color": colours[i % len(colours)], "ls": "-" if m in ours else "--",
                "marker": "o" if m in ours else "s", "ms": 6} for i, m in enumerate(methods)}


def _legend(legend_cell: Any, axes: list[Any], extra: str) -> None:
    seen: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(label, handle)
    legend_cell.legend(list(seen.values()), list(seen), loc="center", title=extra, frameon=False)


def work_precision(rows: Sequence[Row], path: Path) -> None:
    """Hand error against wall time per simulated second, one panel per case, one line per method."""
    require()
    cases = list(dict.fromkeys(r.case for r in rows))
    with slide_style():
        fig = slide_figure()
        axes, legend_cell = _grid(fig, len(cases))
        styles = _styles(rows)
        for ax, case in zip(axes, cases, strict=True):
            for method, style in styles.items():
                pts = sorted((r.time_per_sim_s, max(r.hand_error, FLOOR)) for r in rows
                             if r.case == case and r.method == method and _usable(r))
                if pts:
                    ax.loglog([p[0] * 1e3 for p in pts], [p[1] for p in pts], label=method, **style)
            ax.axhline(1e-4, color="grey", lw=1.2, ls=":")
            ax.set_title(case)
            ax.set_xlabel("ms of wall time per simulated s")
            ax.set_ylabel(ERROR_LABEL)
        _legend(legend_cell, axes, "dotted line: 0.1 mm")
        fig.suptitle("Work-precision: one arm stepped as the game steps it (lower left is better)")
        save(fig, path)


def convergence(rows: Sequence[Row], path: Path) -> None:
    """Hand error against step size for the fixed-step methods, with reference slopes 1, 2 and 4."""
    require()
    fixed = [r for r in rows if r.dt is not None]
    cases = list(dict.fromkeys(r.case for r in fixed))
    if not cases:
        return
    from ..physics.integrators import SCHEMES

    with slide_style():
        fig = slide_figure()
        axes, legend_cell = _grid(fig, len(cases))
        # Colours as in work_precision, which draws the peers too.
        styles = {m: st for m, st in _styles(rows).items() if any(r.method == m for r in fixed)}
        dts = sorted({r.dt for r in fixed if r.dt is not None})
        lo, hi = dts[0], dts[-1]
        anchor = 1e-2
        for ax, case in zip(axes, cases, strict=True):
            for method, style in styles.items():
                pts = sorted((r.dt, max(r.hand_error, FLOOR)) for r in fixed
                             if r.case == case and r.method == method and _usable(r))
                if pts:
                    ax.loglog([p[0] for p in pts], [p[1] for p in pts], label=method, **style)
            # Reference slopes meet at the largest step and are told apart by their dashes in the
            # legend, not by labels on the panel, where they would sit on the data.
            for order in sorted({s.order for s in SCHEMES.values()}):
                ax.loglog([lo, hi], [anchor * (lo / hi) ** order, anchor], label=f"slope {order} (reference)",
                          **SLOPE_STYLES.get(order, {"color": "grey", "lw": 1.2}))
            ax.set_title(case)
            ax.set_xlabel("step dt (s)")
            ax.set_ylabel(ERROR_LABEL)
        _legend(legend_cell, axes, "grey: error ~ dt, dt², dt⁴")
        fig.suptitle("Convergence: error against step (the steeper, the higher the order)")
        save(fig, path)
