"""The lab's window: the centre-out task seen as in a reaching experiment.

As on a manipulandum under a screen, the player sees no arm, only a cursor: the hand as the
task scores it (rotated, mirrored or shown as joint angles when the block says so). The view
is the workspace around home: the home circle, the target when the go cue comes, a trial
counter with the block's name, the block's one-line instruction, and the four muscle bars.
Keys, pause (p), fullscreen (F11) and quitting (Esc) are the game window's own.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import pygame

from ..game.session import RealTimeDriver
from ..lab.protocol import target_positions
from ..lab.session import HOLD, LabSession
from .frontend import GameWindow
from .render import BACKGROUND, BAR_BACK, FAINT, MUSCLE_COLOURS, TARGET, GameRenderer, Viewport

CAPTION = "armgame lab - reach from home to each target"
HOME = (70, 110, 200)
HIT = (40, 150, 70)
CURSOR = (0, 0, 0)
RING = (225, 225, 230)


class LabRenderer(GameRenderer):
    """Draws one frame of a ``LabSession``; text and fonts cached as the game's renderer does."""

    def draw(self, screen: pygame.Surface, session: LabSession, alpha: float = 1.0,  # type: ignore[override]
             paused: bool = False, name: str | None = None) -> None:
        hx, hy = session.home
        reach = session.protocol.distance
        span = max(0.08, 1.45 * reach)
        view = Viewport.fit(screen.get_size(), (hx - span, hx + span, hy - span, hy + 1.35 * span))
        screen.fill(BACKGROUND)
        for x, y in target_positions(session.protocol, session.home):
            pygame.draw.circle(screen, RING, view.to_screen(x, y), view.length(session.protocol.target_radius), 2)
        home = session.home_target
        holding = session.phase == HOLD and not session.over
        pygame.draw.circle(screen, HOME, view.to_screen(home.x, home.y), view.length(home.radius), 0 if holding else 2)
        if not holding and not session.over:
            target = session.rules.target
            pygame.draw.circle(screen, TARGET, view.to_screen(target.x, target.y), view.length(target.radius))
        pygame.draw.circle(screen, CURSOR, view.to_screen(*session.cursor), view.length(0.006))
        self._hud(screen, view, session)
        if paused:
            self._banner(screen, view, "Paused", "press P to go on")
        elif session.over:
            done = len(session.outcomes)
            self._banner(screen, view, "Done" if session.finished else "Time is up",
                         f"{done} trials, {session.result().hits} hits   -   Esc to quit")

    def _hud(self, screen: pygame.Surface, view: Viewport, session: LabSession) -> None:
        unit = min(screen.get_width(), screen.get_height()) / 800.0
        big, small = max(12, round(30 * unit)), max(10, round(20 * unit))
        x0, y0 = 16 * unit, 12 * unit
        plan = session.plan
        total = len(session.plans)
        number = total if plan is None else plan.index + 1
        block = session.block
        screen.blit(self.text(f"Trial {number} of {total}  -  {block.name}", big), (x0, y0))
        screen.blit(self.text(block.instruction or " ", small), (x0, y0 + 34 * unit))
        if session.outcomes:
            last = session.outcomes[-1]
            seconds = (last.end_step - last.go_step) * session.config.dt
            line, colour = (f"last trial: hit, {seconds:.2f} s", HIT) if last.hit else ("last trial: time out", TARGET)
            screen.blit(self.text(line, small, colour), (x0, y0 + 58 * unit))
        keys = self.key_labels
        help_line = f"{keys[0]}/{keys[1]} shoulder   {keys[2]}/{keys[3]} elbow   space home   p pause   esc quit"
        help_text = self.text(help_line, small, FAINT)
        screen.blit(help_text, (x0, screen.get_height() - help_text.get_height() - 10 * unit))
        bar_w, bar_h, gap = 110 * unit, 10 * unit, 5 * unit
        bx = screen.get_width() - bar_w - 16 * unit
        for i, a in enumerate(session.muscles.activation):
            y = y0 + i * (bar_h + gap)
            label = self.text(keys[i], small)
            screen.blit(label, (bx - label.get_width() - 6 * unit, y - 3 * unit))
            pygame.draw.rect(screen, BAR_BACK, (bx, y, bar_w, bar_h))
            if a > 0.002:
                pygame.draw.rect(screen, MUSCLE_COLOURS[i], (bx, y, max(1.0, bar_w * min(a, 1.0)), bar_h))


class LabWindow(GameWindow):
    """The game window's loop (keys, pause, fullscreen, real-time fixed steps) drawing the lab."""

    def __init__(self, session: LabSession, screen: pygame.Surface, clock: Callable[[], float] = time.perf_counter,
                 fps: int = 60, driver: RealTimeDriver | None = None) -> None:
        super().__init__(session, screen, clock, fps, driver, ask_name=False)
        pygame.display.set_caption(CAPTION)
        self.renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
