"""The windows' frame loop, written once: real time measured, frames counted and paced.

Every window (the game's and the lab's, the demos', the autopilot's, the class's, the menu) runs the
same loop: while it is open, measure the real seconds since the last frame, hand them to the window's
frame (which reads its events, advances and draws), count the frame, and let pygame's clock pace the
next. The window's own parts come in as callables; the loop knows nothing of what is drawn.

Why the real time comes from ``clock`` and not from ``pygame.time.Clock.tick``: ``tick`` sleeps to
pace the frames and returns whole milliseconds, while the windows' physics counts fixed steps from a
clock the tests replace (``FakeClock``), so a test never sleeps and a game is the same at any frame rate.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import pygame


def run_loop(frame: Callable[[float], object], running: Callable[[], bool], *, fps: float | None,
             max_frames: int | None = None, clock: Callable[[], float] = time.perf_counter,
             after_frame: Callable[[], object] | None = None) -> int:
    """Call ``frame(seconds since the last frame)`` while ``running()`` and fewer than ``max_frames`` frames
    (None: no limit) have run, then ``after_frame()`` (a screenshot, say), then wait for the next frame at
    ``fps`` frames a second (None or 0: no wait). Returns the number of frames run."""
    pacer = pygame.time.Clock()
    last = clock()
    frames = 0
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
