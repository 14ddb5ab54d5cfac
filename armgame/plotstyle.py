"""The look of every figure armgame writes: a 16:9 slide, 1920 x 1080 px, legible from the back row.

Figures are built on ``matplotlib.figure.Figure`` rather than pyplot, so no GUI backend or global
state is touched and a headless run never needs a display. matplotlib is the optional ``plot``
extra; it is imported only when a figure is asked for.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .errors import UserError

#: Inches and dots per inch: 16 x 9 in at 120 dpi is a 1920 x 1080 px PNG, so a point on the page
#: is a point on a 1920 px wide slide.
SLIDE_INCHES = (16.0, 9.0)
SLIDE_DPI = 120
#: No text smaller than this (pt at 1920 px wide); tests hold every figure to it.
MIN_FONT_PT = 10.0
STYLE = {
    "font.size": 15,
    "axes.titlesize": 16,
    "axes.labelsize": 15,
    "xtick.labelsize": 13,
    "ytick.labelsize": 13,
    "legend.fontsize": 13,
    "figure.titlesize": 18,
    "lines.linewidth": 2.0,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
}


def require_matplotlib(extra: str = "plot", alternative: str = "pass --no-figures") -> None:
    """Fail now, in one line, if matplotlib is missing (before any work is done)."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise UserError(f"figures need matplotlib: pip install 'armgame[{extra}]' (or {alternative})") from None


@contextlib.contextmanager
def slide_style() -> Iterator[None]:
    """Build and save figures inside this: matplotlib reads its settings when artists are made."""
    import matplotlib

    with matplotlib.rc_context(STYLE):
        yield


def slide_figure(width: float = SLIDE_INCHES[0], height: float = SLIDE_INCHES[1]) -> Any:
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), dpi=SLIDE_DPI, layout="constrained")


def save(fig: Any, path: Path) -> Path:
    """Write ``fig`` at slide resolution: only to a regular file, whole or not at all (a planted
    symlink, FIFO or device at ``path`` is refused in one line)."""
    from .records.storage import save_figure

    try:
        return save_figure(fig, path, dpi=SLIDE_DPI)
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None


def smallest_font_pt(fig: Any) -> float:
    """The smallest size (pt) of any visible, non-empty text in ``fig``: for tests and for checking by eye."""
    from matplotlib.text import Text

    sizes = [t.get_fontsize() for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()]
    return min(sizes) if sizes else float("inf")
