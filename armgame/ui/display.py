"""Opening a window that fits the screen it is on, and refusing one nobody can see.

``pygame.display.init`` and ``pygame.font.init`` only: ``pygame.init()`` would start every subsystem,
the mixer too. Where there is no display (no X11 or Wayland session), SDL falls back to its invisible
"offscreen" driver rather than failing, and a window would run unseen; unless that driver was asked
for by name (``SDL_VIDEODRIVER``, as the tests ask for "dummy"), it is refused in one line.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import pygame

from ..errors import UserError

#: Drivers that draw nowhere a person can see.
INVISIBLE_DRIVERS = ("offscreen", "dummy", "evdev")
#: Room left for the title bar and a task bar when a window must fit the desktop.
DECORATION = (0, 64)


@contextlib.contextmanager
def quiet_stderr(quiet: bool = True) -> Iterator[None]:
    """Hide what C libraries print to stderr (libwayland's "XDG_RUNTIME_DIR is invalid" while SDL probes
    for a display that is not there): the user gets our one line instead."""
    if not quiet:
        yield
        return
    try:
        sys.stderr.flush()
        saved = os.dup(2)
        null = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        yield
        return
    try:
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


def init_display(hint: str = "use --headless where there is no display") -> None:
    no_display = sys.platform.startswith("linux") and not (
        os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY") or os.environ.get("SDL_VIDEODRIVER"))
    try:
        with quiet_stderr(no_display):
            pygame.display.init()
        pygame.font.init()
    except pygame.error as exc:
        raise UserError(f"cannot open a window ({exc}); {hint}") from None
    driver = (pygame.display.get_driver() or "").lower()
    asked = os.environ.get("SDL_VIDEODRIVER", "").lower()
    if driver in INVISIBLE_DRIVERS and driver not in asked:
        pygame.display.quit()
        raise UserError(f"cannot open a window (no display: SDL chose its invisible {driver!r} driver); {hint}")


def desktop_size() -> tuple[int, int]:
    try:
        sizes = pygame.display.get_desktop_sizes()
    except pygame.error:
        sizes = []
    return sizes[0] if sizes and min(sizes[0]) > 0 else (1024, 768)


def fit_size(wanted: tuple[int, int] | None, default: tuple[int, int], desktop: tuple[int, int]) -> tuple[int, int]:
    """``wanted`` (or ``default``) shrunk, keeping its shape, to fit ``desktop`` less its decorations."""
    w, h = wanted or default
    room_w, room_h = max(320, desktop[0] - DECORATION[0]), max(240, desktop[1] - DECORATION[1])
    scale = min(1.0, room_w / w, room_h / h)
    return max(1, round(w * scale)), max(1, round(h * scale))


def open_window(size: tuple[int, int] | None = None, fullscreen: bool = False, caption: str = "armgame",
                default: tuple[int, int] = (1024, 720),
                hint: str = "use --headless where there is no display") -> pygame.Surface:
    """A resizable window of ``size`` (fitted to the desktop), or the whole screen."""
    init_display(hint)
    pygame.display.set_caption(caption)
    try:
        if fullscreen:
            return pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
        return pygame.display.set_mode(fit_size(size, default, desktop_size()), pygame.RESIZABLE)
    except pygame.error as exc:
        pygame.display.quit()
        raise UserError(f"cannot open a window ({exc}); {hint}") from None


def toggle_fullscreen(windowed_size: tuple[int, int]) -> pygame.Surface:
    """F11: to the whole screen, or back to a window of ``windowed_size``."""
    surface = pygame.display.get_surface()
    if surface is not None and surface.get_flags() & pygame.FULLSCREEN:
        return pygame.display.set_mode(fit_size(windowed_size, windowed_size, desktop_size()), pygame.RESIZABLE)
    return pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
