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
from ..words import plural
from .frontend import GameWindow
from .render import MIN_TEXT_AT_720, GameRenderer, Hud, Viewport

CAPTION = "armgame lab - reach from home to each target"
HOME = (0, 114, 178)  # Okabe-Ito blue: told apart from the (vermilion) target by colour-blind players too
HIT = (0, 128, 90)
CURSOR = (0, 0, 0)
RING = (205, 210, 218)


class LabRenderer(GameRenderer):
    """Draws one frame of a ``LabSession``; text and fonts cached as the game's renderer does."""

    #: What drives the run: "LAB" (a person at the keys), "AUTOPILOT: NAME", "REPLAY", or "" (a program).
    mode = "LAB"

    def draw(self, screen: pygame.Surface, session: LabSession, alpha: float = 1.0,  # type: ignore[override]
             hud: Hud | None = None) -> None:
        hud = hud or Hud()
        p = self.palette
        hx, hy = session.home
        reach = session.protocol.distance
        span = max(0.08, 1.45 * reach)
        view = Viewport.fit(screen.get_size(), (hx - span, hx + span, hy - span, hy + 1.35 * span))
        screen.fill(p.scene)
        for x, y in target_positions(session.protocol, session.home):
            pygame.draw.circle(screen, RING, view.to_screen(x, y), view.length(session.protocol.target_radius), 2)
        home = session.home_target
        holding = session.phase == HOLD and not session.over
        pygame.draw.circle(screen, HOME, view.to_screen(home.x, home.y), view.length(home.radius), 0 if holding else 3)
        if not holding and not session.over:
            target = session.rules.target
            pygame.draw.circle(screen, p.target, view.to_screen(target.x, target.y), view.length(target.radius))
        pygame.draw.circle(screen, CURSOR, view.to_screen(*session.cursor), view.length(0.006))
        self._hud(screen, session)
        if hud.paused and not hud.ended:
            self._panel(screen, "Paused", "press P to go on")
        elif session.over:
            done = len(session.outcomes)
            self._panel(screen, "Done" if session.finished else "Time is up",
                        f"{plural(done, 'trial')}, {plural(session.result().hits, 'hit')}   -   Esc to quit")

    def _text_heights(self, screen: pygame.Surface) -> tuple[int, int, int]:
        """Text heights (big, normal, small) for this window: never below the projector minimum."""
        h = screen.get_height()
        small = max(MIN_TEXT_AT_720 * h // 720, 14, round(h / 40))
        return round(small * 1.6), round(small * 1.2), small

    def _panel(self, screen: pygame.Surface, title: str, subtitle: str) -> None:
        big, normal, _ = self._text_heights(screen)
        head, sub = self.text(title, big), self.text(subtitle, normal, self.palette.faint)
        pad = normal
        panel = pygame.Rect(0, 0, max(head.get_width(), sub.get_width()) + 2 * pad,
                            head.get_height() + sub.get_height() + 3 * pad)
        panel.center = screen.get_rect().center
        pygame.draw.rect(screen, self.palette.panel, panel, border_radius=pad // 2)
        pygame.draw.rect(screen, self.palette.edge, panel, 2, border_radius=pad // 2)
        screen.blit(head, head.get_rect(midtop=(panel.centerx, panel.top + pad)))
        screen.blit(sub, sub.get_rect(midbottom=(panel.centerx, panel.bottom - pad)))

    def _hud(self, screen: pygame.Surface, session: LabSession) -> None:
        p = self.palette
        big, normal, small = self._text_heights(screen)
        margin = small
        plan = session.plan
        total = len(session.plans)
        number = total if plan is None else plan.index + 1
        block = session.block
        y = margin
        title = self.text(f"Trial {number} of {total}  -  {block.name}", big)
        screen.blit(title, (margin, y))
        y += title.get_height() + small // 3
        if block.instruction:
            screen.blit(self.text(self.fit_text(block.instruction, normal, screen.get_width() - 2 * margin), normal),
                        (margin, y))
            y += normal + small // 3
        if session.outcomes:
            last = session.outcomes[-1]
            seconds = (last.end_step - last.go_step) * session.config.dt
            line, colour = (f"last trial: hit, {seconds:.2f} s", HIT) if last.hit else ("last trial: time out", p.warn)
            screen.blit(self.text(line, small, colour), (margin, y))
        keys = self.key_labels
        if self.mode == "LAB":
            help_line = f"{keys[0]}/{keys[1]} shoulder   {keys[2]}/{keys[3]} elbow   space home   p pause   esc quit"
        elif self.mode:  # a bot or a replay drives: the muscle keys do nothing
            help_line = f"{self.mode}   p pause   esc quit"
        else:  # frames for a program (the Gymnasium env): no keys at all
            help_line = " "
        help_text = self.text(self.fit_text(help_line, small, screen.get_width() - 2 * margin), small, p.faint)
        screen.blit(help_text, (margin, screen.get_height() - help_text.get_height() - margin))
        bar_w, bar_h, gap = 6 * small, small * 2 // 3, small // 2
        bx = screen.get_width() - bar_w - margin
        by = screen.get_height() - help_text.get_height() - 2 * margin - 4 * (bar_h + gap)
        for i, a in enumerate(session.muscles.activation):
            row = by + i * (bar_h + gap)
            label = self.text(keys[i], small)
            screen.blit(label, (bx - label.get_width() - small // 2, row + (bar_h - label.get_height()) // 2))
            pygame.draw.rect(screen, p.bar_back, (bx, row, bar_w, bar_h))
            if a > 0.002:
                pygame.draw.rect(screen, p.muscles[i], (bx, row, max(1.0, bar_w * min(a, 1.0)), bar_h))


class LabWindow(GameWindow):
    """The game window's loop (keys, pause, fullscreen, real-time fixed steps) drawing the lab."""

    def __init__(self, session: LabSession, screen: pygame.Surface, clock: Callable[[], float] = time.perf_counter,
                 fps: int = 60, driver: RealTimeDriver | None = None, mode: str = "LAB") -> None:
        """``mode``: "LAB" for a person at the keys, else what drives it ("AUTOPILOT: adaptive", "REPLAY")."""
        super().__init__(session, screen, clock, fps, driver, ask_name=False, mode=mode, countdown=False)
        pygame.display.set_caption(CAPTION)
        self.renderer = LabRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
        self.renderer.mode = mode
