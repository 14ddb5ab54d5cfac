"""The windows' frame loop, written once: real time measured, frames counted and paced.

Every window (the game's and the lab's, the demos', the autopilot's, the class's, the menu) runs the
same loop: while it is open, measure the real seconds since the last frame, hand them to the window's
frame (which reads its events, advances and draws), count the frame, and let pygame's clock pace the
next. The window's own parts come in as callables; the loop knows nothing of what is drawn.

Why the real time comes from ``clock`` and not from ``pygame.time.Clock.tick``: ``tick`` sleeps to
pace the frames and returns whole milliseconds, while the windows' physics counts fixed steps from a
clock the tests replace (``FakeClock``), so a test never sleeps and a game is the same at any frame rate.

Ctrl-C in the terminal: a window that passes ``on_interrupt`` ends as its close button ends it (the game
window keeps the game's replay and prints its score), at the end of the frame under way, so no frame is
left half done; a second Ctrl-C raises ``KeyboardInterrupt`` as usual, for a loop that does not stop.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Callable, Iterator

import pygame


def run_loop(frame: Callable[[float], object], running: Callable[[], bool], *, fps: float | None,
             max_frames: int | None = None, clock: Callable[[], float] = time.perf_counter,
             after_frame: Callable[[], object] | None = None,
             on_interrupt: Callable[[], object] | None = None) -> int:
    """Call ``frame(seconds since the last frame)`` while ``running()`` and fewer than ``max_frames`` frames
    (None: no limit) have run, then ``after_frame()`` (a screenshot, say), then wait for the next frame at
    ``fps`` frames a second (None or 0: no wait). Returns the number of frames run. ``on_interrupt``: called on
    the first Ctrl-C instead of raising (it should only ask the window to stop: ``running()`` then says no)."""
    pacer = pygame.time.Clock()
    last = clock()
    frames = 0
    with interrupt_calls(on_interrupt):
        while running() and (max_frames is None or frames < max_frames):
            now = clock()
            frame(now - last)
            last = now
            frames += 1
            if after_frame is not None:
                after_frame()
            if fps:
                pacer.tick(fps)
    return frames


@contextlib.contextmanager
def interrupt_calls(stop: Callable[[], object] | None) -> Iterator[None]:
    """Within the block, the first SIGINT (Ctrl-C, on every platform) calls ``stop`` and the next raises
    ``KeyboardInterrupt``; the handler before is put back after. Only the main thread can set a handler, so
    elsewhere (and with ``stop`` None) Ctrl-C raises as usual."""
    if stop is None or threading.current_thread() is not threading.main_thread():
        yield
        return
    asked = False

    def handler(_signum: int, _frame: object) -> None:
        nonlocal asked
        if asked:
            raise KeyboardInterrupt
        asked = True
        stop()

    before = signal.signal(signal.SIGINT, handler)
    try:
        yield
    finally:
        # None: a handler set outside Python, which cannot be put back; Python's own is the next best.
        signal.signal(signal.SIGINT, before if before is not None else signal.default_int_handler)
