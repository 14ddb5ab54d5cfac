"""Opening a window that fits the screen it is on, and refusing one nobody can see.

``pygame.display.init`` and ``pygame.font.init`` only: ``pygame.init()`` would start every subsystem,
the mixer too. Where there is no display (no X11 or Wayland session), SDL falls back to its invisible
"offscreen" driver rather than failing, and a window would run unseen; unless that driver was asked
for by name (``SDL_VIDEODRIVER``, as the tests ask for "dummy"), it is refused in one line
(``NoDisplayError``, to which the command line adds the command that runs without a window), with
nothing SDL printed while probing before it.
"""

from __future__ import annotations

import contextlib
import os
import sys
import tempfile
from collections.abc import Iterator

os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
import pygame

from ..errors import NoDisplayError

#: Drivers that draw nowhere a person can see.
INVISIBLE_DRIVERS = ("offscreen", "dummy", "evdev")
#: Room left for the title bar and a task bar when a window must fit the desktop.
DECORATION = (0, 64)
#: The most of SDL's held-back stderr shown again when a window opens after all.
MAX_HELD_BYTES = 64 * 1024


class HeldOutput:
    """What was written to stderr (fd 2) inside ``held_stderr``: available once the block is left."""

    text = ""


@contextlib.contextmanager
def held_stderr() -> Iterator[HeldOutput]:
    """Hold back what C libraries write to stderr inside the block, to show only if it matters.

    SDL probing for a display that is not there makes libwayland print "error: XDG_RUNTIME_DIR is
    invalid or not set in the environment" (with ``DISPLAY`` set to a server that is gone, or with
    none), which would come before armgame's own one line. The caller shows ``text`` when the window
    opens after all, so nothing is lost where there is a display. Where fd 2 cannot be duplicated
    (a Windows GUI program has no stderr), nothing is held.
    """
    held = HeldOutput()
    try:
        if sys.stderr is not None:
            sys.stderr.flush()
        saved = os.dup(2)
    except (OSError, ValueError):
        yield held
        return
    try:
        with tempfile.TemporaryFile() as sink:
            os.dup2(sink.fileno(), 2)
            try:
                yield held
            finally:
                os.dup2(saved, 2)
                sink.seek(0)
                held.text = sink.read(MAX_HELD_BYTES).decode(errors="replace")
    finally:
        os.close(saved)


def init_display() -> None:
    """Start SDL's display (and fonts), or raise ``NoDisplayError`` in one line: nothing before it."""
    with held_stderr() as noise:
        try:
            pygame.display.init()
            pygame.font.init()
        except pygame.error as exc:
            raise NoDisplayError(f"cannot open a window ({exc})") from None
    driver = (pygame.display.get_driver() or "").lower()
    asked = os.environ.get("SDL_VIDEODRIVER", "").lower()
    if driver in INVISIBLE_DRIVERS and driver not in asked:
        pygame.display.quit()
        raise NoDisplayError(f"cannot open a window (no display: SDL chose its invisible {driver!r} driver)")
    if noise.text and sys.stderr is not None:  # a display after all: whatever SDL said may matter
        sys.stderr.write(noise.text)


def desktop_size() -> tuple[int, int]:
    try:
        sizes = pygame.display.get_desktop_sizes()
    except pygame.error:
        sizes = []
    return sizes[0] if sizes and min(sizes[0]) > 0 else (1024, 768)


def fit_size(wanted: tuple[int, int] | None, default: tuple[int, int], desktop: tuple[int, int]) -> tuple[int, int]:
    """``wanted`` shrunk, keeping its shape, to fit ``desktop`` less its decorations; with nothing wanted,
    ``default``'s shape as large as that room allows: a projector's window fills its width or its height
    (whichever binds: 90% of the desktop or more), never a small box in the middle of the wall."""
    w, h = wanted or default
    room_w, room_h = max(320, desktop[0] - DECORATION[0]), max(240, desktop[1] - DECORATION[1])
    scale = min(room_w / w, room_h / h)
    if wanted is not None:
        scale = min(1.0, scale)
    return max(1, round(w * scale)), max(1, round(h * scale))


def open_window(size: tuple[int, int] | None = None, fullscreen: bool = False, caption: str = "armgame",
                default: tuple[int, int] | None = (1024, 720)) -> pygame.Surface:
    """A resizable window of ``size`` (fitted to the desktop), or the whole screen. With no ``size``, one
    of ``default``'s shape; ``default=None``: the desktop's own shape (a 4:3 projector, a 4:3 window)."""
    init_display()
    pygame.display.set_caption(caption)
    try:
        if fullscreen:
            return pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
        desktop = desktop_size()
        shape = default or (max(320, desktop[0] - DECORATION[0]), max(240, desktop[1] - DECORATION[1]))
        return pygame.display.set_mode(fit_size(size, shape, desktop), pygame.RESIZABLE)
    except pygame.error as exc:
        pygame.display.quit()
        raise NoDisplayError(f"cannot open a window ({exc})") from None


def toggle_fullscreen(windowed_size: tuple[int, int]) -> pygame.Surface:
    """F11: to the whole screen, or back to a window of ``windowed_size``."""
    surface = pygame.display.get_surface()
    if surface is not None and surface.get_flags() & pygame.FULLSCREEN:
        return pygame.display.set_mode(fit_size(windowed_size, windowed_size, desktop_size()), pygame.RESIZABLE)
    return pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
