"""Speed of the game itself: headless play against real time, frame cost, start-up.

    python benchmarks/game_speed.py            # dummy video driver (and a real X11 window if DISPLAY is set)
    xvfb-run -a python benchmarks/game_speed.py

Each figure is a median of repeats measured in this one run; the goals are ratios, not
timed tests, because the machines are shared and noisy.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import time

from armgame.game.rules import GameConfig
from armgame.game.session import GameSession, InputEvent

# A busy 60 s game: muscles switching every 0.2 s, resets now and then.
KEYS = ("d", "f", "j", "k")


def busy_timeline(dt: float, seconds: float = 60.0) -> list[InputEvent]:
    events = []
    step = round(0.2 / dt)
    for i, start in enumerate(range(0, round(seconds / dt), step)):
        key = KEYS[i % 4]
        events += [InputEvent(start, key, "down"), InputEvent(start + step // 2, key, "up")]
        if i % 50 == 49:
            events.append(InputEvent(start + step // 2, "space", "down"))
    return events


def headless_game_speed(repeats: int = 5, compiled: bool = True) -> dict[str, float]:
    """The busy game headless; ``compiled=False``: ``GameSession``'s Python loop (no C compiler at install)."""
    config = GameConfig(time_limit=60.0)
    timeline = busy_timeline(config.dt)
    times = []
    for _ in range(repeats):
        session = GameSession(config, compiled=compiled)
        start = time.perf_counter()
        session.play(timeline)
        times.append(time.perf_counter() - start)
    wall = statistics.median(times)
    return {"game_seconds": 60.0, "wall_seconds": wall, "times_real_time": 60.0 / wall,
            "physics_rate_hz": 1.0 / config.dt, "integrator": config.integrator,
            "loop": "compiled" if session._compiled is not None else "python"}


def frame_cost(driver: str, frames: int = 300, size: tuple[int, int] = (800, 800)) -> dict[str, float]:
    """Median cost of one full frame (draw and flip) at ``size``, in a child process per driver.

    The frame drawn is a busy one: muscles active, the HUD, a hit's flash and "+1", and a second of
    hand trail (``--trail``), so the figure bounds what a player's frame costs.
    """
    code = f"""
import os, time, statistics, json
os.environ['SDL_VIDEODRIVER'] = {driver!r}
import pygame
from armgame.ui.display import init_display
from armgame.ui.render import GameRenderer, Hud
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
session = GameSession(GameConfig())
session.key_event('d', 'down'); session.key_event('k', 'down')
init_display()
screen = pygame.display.set_mode({size!r})
renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
help_ = ('d/f shoulder', 'j/k elbow', 'space reset (-1)', 'tab hide arm', 'p pause', 'm mute', 'F11 fullscreen',
         'Esc quit')
plain = []
for i in range({frames}):
    t0 = time.perf_counter()
    screen.fill((255, 255, 255))
    pygame.draw.circle(screen, (0, 0, 0), (400, 400), 30)
    pygame.display.flip()
    plain.append(time.perf_counter() - t0)
draw, whole, trail = [], [], []
for i in range({frames}):
    session.advance(4)
    trail = (trail + [session.hand()])[-60:]
    target = session.rules.target
    hud = Hud(details=('seed 10',), help=help_, hits=[(target.x, target.y, (i % 60) / 60)], trail=trail)
    t0 = time.perf_counter()
    renderer.draw(screen, session, 0.5, hud)
    t1 = time.perf_counter()
    pygame.display.flip()
    t2 = time.perf_counter()
    draw.append(t1 - t0); whole.append(t2 - t0)
print(json.dumps({{'draw_ms': statistics.median(draw) * 1e3, 'frame_ms': statistics.median(whole) * 1e3,
                  'plain_frame_ms': statistics.median(plain) * 1e3,
                  'draw_p90_ms': statistics.quantiles(draw, n=10)[-1] * 1e3}}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=dict(os.environ))
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr.strip() else "failed"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def startup_to_first_frame(driver: str, repeats: int = 5) -> float:
    code = f"""
import os, time
t0 = time.perf_counter()
os.environ['SDL_VIDEODRIVER'] = {driver!r}
from armgame.commands.play import DEFAULT_SEED
from armgame.game.rules import GameConfig
from armgame.game.session import GameSession
from armgame.ui.frontend import GameWindow, open_window
session = GameSession(GameConfig(seed=DEFAULT_SEED))
window = GameWindow(session, open_window((800, 800)))  # countdown and all, as `armgame play` starts
window.frame(0.0)
print(time.perf_counter() - t0)
"""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def help_imports() -> list[str]:
    code = ("import sys\nfrom armgame.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass\n"
            "print(','.join(m for m in ('numpy', 'scipy', 'pygame') if m in sys.modules), file=sys.stderr)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    return [m for m in out.stderr.strip().splitlines()[-1].split(",") if m] if out.stderr.strip() else []


def main() -> None:
    for compiled in (True, False):
        game = headless_game_speed(compiled=compiled)
        print(f"headless 60 s game, {game['loop']} loop: {game['wall_seconds'] * 1e3:.1f} ms wall, "
              f"{game['times_real_time']:.0f}x real time ({game['integrator']} at {game['physics_rate_hz']:.0f} Hz)")
    drivers = ["dummy"] + (["x11"] if os.environ.get("DISPLAY") else [])
    for driver in drivers:
        for size in ((800, 800), (1920, 1080)):  # the goal: under 2 ms a frame at 1920x1080
            cost = frame_cost(driver, size=size)
            if "error" in cost:
                print(f"frame, {driver}: {cost['error']}")
                continue
            print(f"frame {size[0]}x{size[1]}, {driver}: {cost['frame_ms']:.2f} ms (drawing {cost['draw_ms']:.2f} ms, "
                  f"90th percentile {cost['draw_p90_ms']:.2f} ms; the rest display.flip); a plain frame (fill, one "
                  f"circle, flip): {cost['plain_frame_ms']:.2f} ms")
        print(f"start-up to first frame, {driver}: {startup_to_first_frame(driver) * 1e3:.0f} ms")
    heavy = help_imports()
    print(f"armgame --help imports: {', '.join(heavy) if heavy else 'none of numpy, scipy, pygame'}")


if __name__ == "__main__":
    main()
