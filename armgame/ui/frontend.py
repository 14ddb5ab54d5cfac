"""The game window: keyboard in, frames out, physics at its own fixed rate.

Real elapsed time comes from ``time.perf_counter`` (injectable for tests), never from
``pygame.time.Clock``, which sleeps to whole milliseconds; the clock only caps the frame
rate. Keys become session events at the physics step they arrive before.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import pygame

from ..game.session import DOWN, UP, GameSession, RealTimeDriver
from .render import GameRenderer

CAPTION = "armgame - hit the red targets with the black dot"
DEFAULT_SIZE = (800, 800)
NAME_LENGTH = 24
#: Keys still being mashed as the clock runs out must not type themselves into the name.
NAME_ENTRY_DELAY = 0.5


def open_window(size: tuple[int, int] = DEFAULT_SIZE, fullscreen: bool = False) -> pygame.Surface:
    # display and font only: pygame.init() would also start the mixer, which the game never uses.
    pygame.display.init()
    pygame.font.init()
    pygame.display.set_caption(CAPTION)
    flags = pygame.FULLSCREEN if fullscreen else pygame.RESIZABLE
    return pygame.display.set_mode((0, 0) if fullscreen else size, flags)


def key_name(event: pygame.event.Event) -> str:
    return pygame.key.name(event.key).lower()


class GameWindow:
    """Runs one game in a window until the player quits; ``run`` returns the session."""

    def __init__(
        self,
        session: GameSession,
        screen: pygame.Surface,
        clock: Callable[[], float] = time.perf_counter,
        fps: int = 60,
        driver: RealTimeDriver | None = None,
        ask_name: bool = False,
    ) -> None:
        self.session = session
        self.screen = screen
        self.clock = clock
        self.fps = fps
        # A driver given from outside (a replay's timeline) is the only input: keys just pause and quit.
        self.keyboard = driver is None
        self.driver = driver or RealTimeDriver(session)
        #: The name typed on the end screen while it is being typed (None: no prompt), and once confirmed.
        self.name_entry: str | None = None
        self.player_name: str | None = None
        self.ask_name = ask_name
        self._over_for = 0.0
        names = tuple(m.name for m in session.config.muscles)
        self.renderer = GameRenderer(session.muscles.keys, names)
        self.paused = False
        self.running = True
        self.fullscreen = bool(screen.get_flags() & pygame.FULLSCREEN)
        self.alpha = 1.0

    def handle(self, event: pygame.event.Event) -> None:
        if event.type == pygame.QUIT:
            self.running = False
        elif self.name_entry is not None and event.type in (pygame.TEXTINPUT, pygame.KEYDOWN):
            self._type_name(event)
        elif event.type == pygame.KEYDOWN:
            name = key_name(event)
            if name == "escape":
                self.running = False
            elif name == "p" and not self.session.over:
                self.set_paused(not self.paused)
            elif name == "f11":
                self._toggle_fullscreen()
            elif not self.paused and self.keyboard:
                self.session.key_event(name, DOWN)
        elif event.type == pygame.KEYUP and not self.paused and self.keyboard:
            self.session.key_event(key_name(event), UP)
        elif event.type == pygame.WINDOWFOCUSLOST and not self.session.over:
            self.set_paused(True)

    def _type_name(self, event: pygame.event.Event) -> None:
        if event.type == pygame.TEXTINPUT:
            if self._over_for >= NAME_ENTRY_DELAY:
                typed = "".join(c for c in event.text if c.isprintable())
                self.name_entry = (self.name_entry + typed)[:NAME_LENGTH]
            return
        name = key_name(event)
        if name == "escape":
            self.running = False
        elif name == "backspace":
            self.name_entry = self.name_entry[:-1]
        elif name in ("return", "enter") and self.name_entry.strip():
            self.player_name = self.name_entry.strip()
            self.running = False
        elif name == "f11":
            self._toggle_fullscreen()

    def set_paused(self, paused: bool) -> None:
        if paused and self.keyboard:
            # A key released while paused (or while the window is away) would otherwise stay held.
            for key, held in zip(self.session.muscles.keys, self.session.held, strict=True):
                if held:
                    self.session.key_event(key, UP)
        self.paused = paused

    def _toggle_fullscreen(self) -> None:
        self.fullscreen = not self.fullscreen
        if self.fullscreen:
            self.screen = pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
        else:
            self.screen = pygame.display.set_mode(DEFAULT_SIZE, pygame.RESIZABLE)

    def frame(self, elapsed: float) -> None:
        """Handle pending events, advance physics by ``elapsed`` real seconds, draw."""
        for event in pygame.event.get():
            self.handle(event)
        if self.paused:
            elapsed = 0.0
        if not self.session.over:
            self.alpha = self.driver.advance(elapsed)
        else:
            self.alpha = 1.0
            self._over_for += elapsed
            if self.ask_name and self.name_entry is None and self.player_name is None:
                self.name_entry = ""
                pygame.key.start_text_input()
        self.renderer.draw(self.screen, self.session, self.alpha, self.paused, self.name_entry)
        pygame.display.flip()

    def run(self, max_frames: int | None = None) -> GameSession:
        limiter = pygame.time.Clock()
        last = self.clock()
        frames = 0
        while self.running and (max_frames is None or frames < max_frames):
            now = self.clock()
            self.frame(now - last)
            last = now
            frames += 1
            if self.fps:
                limiter.tick(self.fps)
        return self.session
