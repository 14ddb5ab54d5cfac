"""The autopilot demo's window: the model and naive bots play the same game side by side.

Each half is a game drawn by the game's own renderer (``GameRenderer``), labelled with its bot, under
one caption that says what the class is comparing. The halves are laid out from the window's size,
so the two games and their scores fit a 1280 x 720 or 1366 x 768 projector (on a tall screen one
above the other); F11 fills the screen.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import pygame

from ..game.bots import BOT_NAMES, Autopilot, make_bot
from ..game.rules import GameConfig
from ..game.session import GameSession, RealTimeDriver
from .display import open_window, toggle_fullscreen
from .loop import run_loop
from .playback import MAX_FRAME, PLAYBACK_HELP, REPLAY_SPEEDS, SKIP_SECONDS, skip_sign, speed_after
from .render import PALETTES, GameRenderer, Hud, Label, text_heights

CAPTION = ("Same targets, same planner. {0}: the bot knows the interaction torques. "
           "{1}: it drives each joint as if the other did not move.")
#: The keys, as the help line says them: the same set as the demos' and the replays'.
HELP = ("p pause", "r restart", *PLAYBACK_HELP, "F11 fullscreen", "Esc quit")
WHO = {"model": "AUTOPILOT: model", "naive": "AUTOPILOT: naive"}


@dataclass
class Game:
    name: str
    session: GameSession
    driver: RealTimeDriver
    renderer: GameRenderer


class AutopilotWindow:
    def __init__(self, seed: int, duration: float, screen: pygame.Surface,
                 clock: Callable[[], float] = time.perf_counter, palette: str = "okabe-ito",
                 text_scale: float = 1.0) -> None:
        self.seed, self.duration = seed, duration
        self.screen = screen
        self.clock = clock
        # The settings' palette and text scale, as every other window takes them (a projector's room).
        self.palette_name, self.text_scale = palette, text_scale
        self.palette = PALETTES[palette]
        self.windowed_size = screen.get_size()
        self.paused = False
        self.running = True
        self.speed = 1.0
        self.games: list[Game] = []
        #: What never moves, drawn once per window size and pause state (``static_builds`` counts them).
        self._static: pygame.Surface | None = None
        self._static_areas: list[pygame.Rect] = []
        self._static_key: tuple | None = None
        self._shown: object = None
        self.static_builds = 0
        self.restart()

    def restart(self) -> None:
        self.games = []
        for name in BOT_NAMES:
            session = GameSession(GameConfig(seed=self.seed, time_limit=self.duration))
            # Sped up 8 times, a frame covers up to 8 times the usual stall limit.
            driver = RealTimeDriver(Autopilot(session, make_bot(name)), MAX_FRAME * max(REPLAY_SPEEDS))  # type: ignore[arg-type]
            renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles),
                                    self.palette_name, self.text_scale)
            self.games.append(Game(name, session, driver, renderer))

    # ---------------------------------------------------------------- layout
    def layout(self, size: tuple[int, int]) -> tuple[list[Label], list[pygame.Rect], list[Label]]:
        """The caption and help labels, and each game's area, for a window of ``size``.

        Every text, the games' too, is sized for the whole window (``GameRenderer.text_basis``): each game
        gets half of it, but the back row reads them at the window's scale (19 px or more at 768 lines)."""
        w, h = size
        u = min(w, h) / 720.0
        pad, gap = max(6, round(12 * u)), max(4, round(6 * u))
        renderer = self.games[0].renderer
        for game in self.games:
            game.renderer.text_basis = size
        _, caption_h, help_h = text_heights(size, self.text_scale)
        # Side by side on a wide screen, one above the other on a tall one (where neither would fit beside).
        caption = CAPTION.format(*(("Top", "Bottom") if h > w else ("Left", "Right")))
        lines = renderer.wrap_items(re.split(r"(?<=\.) ", caption), caption_h, w - 2 * pad, gap)
        labels: list[Label] = []
        y = pad
        for line in lines:
            labels.append(renderer.label(line, caption_h, self.palette.ink, "caption", midtop=(w // 2, y)))
            y = labels[-1].rect.bottom + gap // 2
        footer: list[Label] = []
        bottom = h - pad
        for line in reversed(renderer.wrap_items(self.help_items(), help_h, w - 2 * pad, gap)):
            footer.append(renderer.label(line, help_h, self.palette.faint, "help", midbottom=(w // 2, bottom)))
            bottom = footer[-1].rect.top - gap // 2
        top, bottom = y + gap, bottom - gap
        if h > w:  # a tall screen: one game above the other, so neither gets narrow
            half = (bottom - top) // 2
            areas = [pygame.Rect(0, top + i * half, w, max(half, 10)) for i in range(2)]
        else:
            half = w // 2
            areas = [pygame.Rect(i * half, top, half, max(bottom - top, 10)) for i in range(2)]
        return labels, areas, footer

    def _static_layer(self, size: tuple[int, int]) -> tuple[pygame.Surface, list[pygame.Rect]]:
        """The window's background, caption and help line, drawn once per size and pause state (the
        help line says "p resume" while paused), and the games' areas."""
        key = (size, self.paused)
        if self._static_key != key:
            labels, areas, footer = self.layout(size)
            layer = pygame.Surface(size)
            layer.fill(self.palette.window)
            renderer = self.games[0].renderer
            for lab in labels + footer:
                layer.blit(renderer.text(lab.text, lab.height, lab.colour), lab.rect)
            self._static, self._static_areas, self._static_key = layer, areas, key
            self.static_builds += 1
        return self._static, self._static_areas

    def all_boxes(self, size: tuple[int, int]) -> list[tuple[str, pygame.Rect]]:
        """Every text and bar rectangle in window coordinates (for the tests)."""
        labels, areas, footer = self.layout(size)
        boxes = [(lab.text, lab.rect) for lab in labels + footer]
        for game, area in zip(self.games, areas, strict=True):
            lay = game.renderer.layout(area.size, game.session, self.hud(game))
            boxes += [(name, rect.move(area.topleft)) for name, rect in lay.boxes()]
        return boxes

    def help_items(self) -> tuple[str, ...]:
        return ("p resume", *HELP[1:]) if self.paused else HELP

    def skip(self, seconds: float) -> None:
        """Both games at once, ``seconds`` on (run at once) or back (replayed from the start: the bots
        are deterministic, so the same moment comes back)."""
        dt = self.games[0].session.config.dt
        target = max(0, self.games[0].session.steps + round(seconds / dt))
        if target < self.games[0].session.steps:
            self.restart()
        for game in self.games:
            autopilot = game.driver.session
            autopilot.advance(max(0, min(target, game.session.total_steps) - game.session.steps))
            game.driver.steps_taken = game.session.steps
            game.driver.clock = game.session.steps * dt

    def hud(self, game: Game) -> Hud:
        return Hud(driver=WHO[game.name], paused=self.paused, ended=game.session.over)

    # ----------------------------------------------------------------- frames
    def handle(self, event: pygame.event.Event) -> None:
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.VIDEORESIZE and not self.screen.get_flags() & pygame.FULLSCREEN:
            self.windowed_size = (event.w, event.h)
        elif event.type == pygame.KEYDOWN:
            key = pygame.key.name(event.key).lower()
            if key == "escape":
                self.running = False
            elif key == "p":
                self.paused = not self.paused
            elif key == "r":
                self.restart()
            elif (speed := speed_after(key, self.speed)) is not None:
                self.speed = speed
            elif skip_sign(key):
                self.skip(SKIP_SECONDS * skip_sign(key))
            elif key == "f11":
                self.screen = toggle_fullscreen(self.windowed_size)

    def frame(self, elapsed: float) -> None:
        for event in pygame.event.get():
            self.handle(event)
        screen = self.screen = pygame.display.get_surface() or self.screen
        layer, areas = self._static_layer(screen.get_size())
        # A new layer, or a window cleared by a change of mode (F11; its corner is the layer's no more):
        # all of it once. The games cover their areas every frame, and nothing else on the window moves.
        shown = (id(layer), id(screen), screen.get_size())
        if self._shown != shown or screen.get_at((0, 0)) != layer.get_at((0, 0)):
            screen.blit(layer, (0, 0))
            self._shown = shown
        for game, area in zip(self.games, areas, strict=True):
            alpha = game.driver.advance(0.0 if self.paused else min(max(elapsed, 0.0), MAX_FRAME) * self.speed) \
                if not game.session.over else 1.0
            game.renderer.draw(screen.subsurface(area), game.session, alpha, self.hud(game))
        end = areas[1].bottomleft if areas[1].left > areas[0].left else areas[1].topright
        pygame.draw.line(screen, self.palette.edge, areas[1].topleft, end,
                         max(1, round(2 * min(screen.get_size()) / 720)))
        pygame.display.flip()

    def hits(self) -> dict[str, int]:
        return {g.name: g.session.rules.board.hits for g in self.games}


def run_window(seed: int, duration: float = 60.0, size: tuple[int, int] | None = None, fullscreen: bool = False,
               max_frames: int | None = None, screenshot: Path | None = None, palette: str = "okabe-ito",
               text_scale: float = 1.0) -> dict[str, int]:
    """Two bot games side by side at real time until Esc or close; returns the hits of each bot."""
    # No size asked: the desktop's own shape (a 4:3 projector gets a 4:3 window, not a 16:9 strip in it).
    screen = open_window(size, fullscreen, "armgame demo: autopilot, model against naive", None)
    window = AutopilotWindow(seed, duration, screen, palette=palette, text_scale=text_scale)
    wanted = [screenshot]

    def shoot() -> None:  # the first frame 20 s into the race
        if wanted[0] is not None and window.games[0].session.time >= 20.0:
            pygame.image.save(window.screen, str(wanted[0]))
            wanted[0] = None

    try:
        run_loop(window.frame, lambda: window.running, fps=60, max_frames=max_frames, clock=window.clock,
                 after_frame=shoot)
    finally:
        result = window.hits()
        pygame.display.quit()
    return result
