"""What one frame of the demo windows costs to draw: the demos' scenes and the autopilot's two games.

    python benchmarks/demo_draw.py                 # 1920 x 1080 and 1024 x 768, SDL's dummy driver
    python benchmarks/demo_draw.py --size 1920x1080 --frames 200

Each figure is the median over ``--frames`` frames of one window's ``draw`` (the demos) or ``frame`` (the
autopilot: its events, both games' steps and drawing), the clock injected so the physics moves as at
60 frames per second, in CPU time (``time.process_time``: a busy shared machine's waits left out).
The goal (issue 27): what never moves is drawn once per window size, so a frame costs what moves;
see docs/performance.md for the figures.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time

os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")

import pygame


def demo_draw_ms(name: str, size: tuple[int, int], frames: int) -> float:
    from armgame.demos.catalog import make_run
    from armgame.ui.demo_window import DemoWindow

    now = [0.0]
    window = DemoWindow(name, make_run(name), clock=lambda: now[0], size=size)
    window.open()
    pygame.display.set_mode(size)
    times = []
    try:
        for _ in range(frames + 5):
            now[0] += 1 / 60
            window.advance()
            start = time.process_time()
            window.draw()
            times.append(time.process_time() - start)
    finally:
        window.close()
    return statistics.median(times[5:]) * 1e3


def autopilot_frame_ms(size: tuple[int, int], frames: int) -> float:
    from armgame.ui.autopilot_window import AutopilotWindow

    pygame.display.init()
    pygame.font.init()
    screen = pygame.display.set_mode(size)
    window = AutopilotWindow(10, 60.0, screen, clock=lambda: 0.0)
    times = []
    try:
        for _ in range(frames + 5):
            start = time.process_time()
            window.frame(1 / 60)
            times.append(time.process_time() - start)
    finally:
        pygame.display.quit()
    return statistics.median(times[5:]) * 1e3


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", action="append", default=None,
                        help="WxH (repeatable; default 1920x1080 and 1024x768)")
    parser.add_argument("--frames", type=int, default=120)
    args = parser.parse_args()
    sizes = [tuple(int(v) for v in s.split("x")) for s in args.size or ["1920x1080", "1024x768"]]
    results = {}
    for size in sizes:
        label = f"{size[0]}x{size[1]}"
        for name in ("planning", "interaction", "chaos"):
            results[f"{name} draw ms at {label}"] = round(demo_draw_ms(name, size, args.frames), 2)
        results[f"autopilot frame ms at {label}"] = round(autopilot_frame_ms(size, args.frames), 2)
    print(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
