"""The autopilot demo: "does the brain know about interaction torques?" as a game between two bots.

Both bots play the same game (same seed, same targets) with the same planner, feedback and key
pressing; ``model`` knows the arm's interaction torques and ``naive`` drives each joint as if
the other did not move (see ``armgame.game.bots``). Headless, it plays 60 s games on seeds 0 to
9 and prints (and with ``--out``, writes) the hits per seed for both; in a window, the two arms
play side by side, each with its score. Only ``run_window`` imports pygame.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from ..errors import UserError
from ..game.bots import BOT_NAMES, Autopilot, make_bot, play_bot
from ..game.rules import GameConfig
from ..game.session import GameSession, RealTimeDriver

TABLE_SEEDS = tuple(range(10))
WINDOW_SEED = 10  # the game's own default seed: the targets a class sees in `armgame play`
CAPTION = "Same targets, same planner. Left knows the interaction torques; right drives each joint alone."


@dataclass(frozen=True)
class Row:
    seed: int
    hits: dict[str, int]

    @property
    def ratio(self) -> float:
        return self.hits["model"] / max(self.hits["naive"], 1)


def hits_table(seeds: tuple[int, ...] = TABLE_SEEDS, duration: float = 60.0) -> list[Row]:
    return [Row(seed, {name: play_bot(GameConfig(seed=seed, time_limit=duration), name).rules.board.hits
                       for name in BOT_NAMES}) for seed in seeds]


def format_table(rows: list[Row], duration: float) -> str:
    lines = [f"hits in {duration:g} s per seed (model knows the interaction torques; naive does not)",
             f"{'seed':>4} {'model':>6} {'naive':>6} {'model/naive':>12}"]
    for r in rows:
        lines.append(f"{r.seed:>4} {r.hits['model']:>6} {r.hits['naive']:>6} {r.ratio:>12.2f}")
    lines.append(f"{'all':>4} {sum(r.hits['model'] for r in rows):>6} {sum(r.hits['naive'] for r in rows):>6} "
                 f"{min(r.ratio for r in rows):>8.2f} min")
    return "\n".join(lines)


def run_headless(out: Path | None, duration: float | None) -> str:
    duration = 60.0 if duration is None else duration
    rows = hits_table(TABLE_SEEDS, duration)
    text = format_table(rows, duration)
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        path = out / "autopilot.csv"
        from ..records.storage import atomic_write_bytes

        try:
            atomic_write_bytes(path, ("seed,duration,model_hits,naive_hits\n" + "".join(
                f"{r.seed},{duration:g},{r.hits['model']},{r.hits['naive']}\n" for r in rows)).encode(), "CSV")
        except OSError as exc:
            raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
        text += f"\nwrote {path}"
    return text


def run_window(seed: int = WINDOW_SEED, duration: float = 60.0, size: tuple[int, int] = (1400, 760),
               max_frames: int | None = None, screenshot: Path | None = None) -> dict[str, int]:
    """Two bot games side by side at real time; Esc quits, p pauses, r restarts. Returns hits per bot."""
    import os

    os.environ.setdefault("PYGAME_HIDE_SUPPORT_PROMPT", "1")
    import pygame

    from ..ui.render import GameRenderer

    pygame.display.init()
    pygame.font.init()
    try:
        screen = pygame.display.set_mode(size, pygame.RESIZABLE)
    except pygame.error as exc:
        raise UserError(f"cannot open a window ({exc}); use --headless where there is no display") from None
    pygame.display.set_caption("armgame demo: autopilot, model against naive")
    font = pygame.font.Font(None, 30)

    def start() -> list[tuple[str, GameSession, RealTimeDriver, GameRenderer]]:
        games = []
        for name in BOT_NAMES:
            session = GameSession(GameConfig(seed=seed, time_limit=duration))
            driver = RealTimeDriver(Autopilot(session, make_bot(name)))  # type: ignore[arg-type]
            renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
            games.append((name, session, driver, renderer))
        return games

    games = start()
    paused, running, frames = False, True, 0
    limiter = pygame.time.Clock()
    last = time.perf_counter()
    try:
        while running and (max_frames is None or frames < max_frames):
            for event in pygame.event.get():
                if event.type == pygame.QUIT:
                    running = False
                elif event.type == pygame.KEYDOWN:
                    key = pygame.key.name(event.key)
                    if key == "escape":
                        running = False
                    elif key in ("p", "space"):
                        paused = not paused
                    elif key == "r":
                        games = start()
            now = time.perf_counter()
            elapsed = 0.0 if paused else now - last
            last = now
            screen = pygame.display.get_surface()
            w, h = screen.get_size()
            screen.fill((255, 255, 255))
            caption_h = 40
            half = w // 2
            for i, (name, session, driver, renderer) in enumerate(games):
                alpha = driver.advance(elapsed) if not session.over else 1.0
                area = screen.subsurface(pygame.Rect(i * half, caption_h, half, h - caption_h))
                renderer.draw(area, session, alpha, paused)
                label = font.render(f"{name}: {session.rules.board.hits} hits", True, (20, 20, 28))
                # Along the bottom: the top of each half is the game's own score and clock.
                screen.blit(label, (i * half + (half - label.get_width()) // 2, h - label.get_height() - 12))
            text = pygame.font.Font(None, 24).render(CAPTION, True, (60, 60, 70))
            screen.blit(text, ((w - text.get_width()) // 2, 10))
            pygame.draw.line(screen, (180, 180, 185), (half, caption_h), (half, h), 2)
            pygame.display.flip()
            frames += 1
            if screenshot is not None and games[0][1].time >= 20.0:
                pygame.image.save(screen, str(screenshot))
                screenshot = None
            limiter.tick(60)
    finally:
        result = {name: session.rules.board.hits for name, session, _, _ in games}
        pygame.display.quit()
    return result
