"""Drawing the game with pygame. The only game module that imports pygame.

The renderer reads a session (and how far between two physics steps the frame falls)
and draws one frame; it never changes the game. The world's view rectangle is scaled to
the largest square that fits the window, so any window size or a projector's fullscreen
shows the same scene.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import pygame

from ..game.session import GameSession
from ..words import plural

BACKGROUND = (255, 255, 255)
LINK = (70, 70, 80)
JOINT = (30, 30, 35)
HAND = (0, 0, 0)
TARGET = (220, 30, 30)
TEXT = (20, 20, 20)
FAINT = (120, 120, 120)
BAR_BACK = (225, 225, 230)
PANEL = (245, 245, 248)
MUSCLE_COLOURS = ((40, 110, 200), (40, 160, 120), (200, 120, 30), (150, 60, 170))


@dataclass(frozen=True)
class Viewport:
    """Maps world metres (x forward, y up) to window pixels (y down)."""

    left: float
    top: float
    scale: float  # pixels per metre
    world: tuple[float, float, float, float]

    @classmethod
    def fit(cls, size: tuple[int, int], world: tuple[float, float, float, float]) -> Viewport:
        xmin, xmax, ymin, ymax = world
        w, h = size
        scale = min(w / (xmax - xmin), h / (ymax - ymin))
        left = (w - scale * (xmax - xmin)) / 2.0
        top = (h - scale * (ymax - ymin)) / 2.0
        return cls(left, top, scale, world)

    def to_screen(self, x: float, y: float) -> tuple[int, int]:
        xmin, _, _, ymax = self.world
        return round(self.left + (x - xmin) * self.scale), round(self.top + (ymax - y) * self.scale)

    def length(self, metres: float) -> int:
        return max(1, round(metres * self.scale))


class GameRenderer:
    """Draws arm, target, HUD and the muscle bars; fonts and text are made once and cached."""

    def __init__(self, key_labels: tuple[str, ...], muscle_names: tuple[str, ...]) -> None:
        self.key_labels = key_labels
        self.muscle_names = muscle_names
        self._fonts: dict[int, pygame.font.Font] = {}
        self._text: dict[tuple[str, int, tuple[int, int, int]], pygame.Surface] = {}

    def _font(self, size: int) -> pygame.font.Font:
        if size not in self._fonts:
            self._fonts[size] = pygame.font.Font(None, size)
        return self._fonts[size]

    def text(self, string: str, size: int, colour: tuple[int, int, int] = TEXT) -> pygame.Surface:
        key = (string, size, colour)
        surface = self._text.get(key)
        if surface is None:
            if len(self._text) > 512:  # the clock makes new strings every frame
                self._text.clear()
            surface = self._text[key] = self._font(size).render(string, True, colour)
        return surface

    def draw(self, screen: pygame.Surface, session: GameSession, alpha: float = 1.0, paused: bool = False,
             name: str | None = None) -> None:
        """One frame; ``name``, when not None, is the player's name being typed on the end screen."""
        view = Viewport.fit(screen.get_size(), session.config.view)
        screen.fill(BACKGROUND)
        arm = session.config.arm
        q1, q2 = session.interpolated_angles(alpha)
        elbow = (arm.l1 * math.cos(q1), arm.l1 * math.sin(q1))
        hand = (elbow[0] + arm.l2 * math.cos(q1 + q2), elbow[1] + arm.l2 * math.sin(q1 + q2))
        target = session.rules.target
        pygame.draw.circle(screen, TARGET, view.to_screen(target.x, target.y), view.length(target.radius))
        if session.rules.arm_visible:
            shoulder_px, elbow_px, hand_px = (view.to_screen(*p) for p in ((0.0, 0.0), elbow, hand))
            width = view.length(0.024)
            pygame.draw.line(screen, LINK, shoulder_px, elbow_px, width)
            pygame.draw.line(screen, LINK, elbow_px, hand_px, width)
            for joint in (shoulder_px, elbow_px):
                pygame.draw.circle(screen, JOINT, joint, view.length(0.016))
        # The hand is the one thing a player must see, arm hidden or not: larger than the link is wide.
        pygame.draw.circle(screen, HAND, view.to_screen(*hand), view.length(0.02))
        self._draw_hud(screen, view, session)
        if paused:
            self._banner(screen, view, "Paused", "press P to play on")
        elif session.over and name is not None:
            self._name_prompt(screen, view, session.rules.board.score, name)
        elif session.over:
            board = session.rules.board
            self._banner(screen, view, f"Your score: {board.score}",
                         f"{plural(board.hits, 'hit')}, {plural(board.resets, 'reset')}   -   Esc to quit")

    def _draw_hud(self, screen: pygame.Surface, view: Viewport, session: GameSession) -> None:
        unit = view.scale / 500.0  # HUD sizes are designed for the 2012 game's 500 px per metre
        big, small = max(12, round(34 * unit)), max(10, round(20 * unit))
        x0, y0 = view.left + 16 * unit, view.top + 12 * unit
        board = session.rules.board
        screen.blit(self.text(f"Score {board.score}", big), (x0, y0))
        clock = self.text(f"Time {session.time_left:4.1f}", big)
        screen.blit(clock, (view.left + view.scale * 1.6 - clock.get_width() - 16 * unit, y0))
        keys = self.key_labels
        help_line = (f"{keys[0]}/{keys[1]} shoulder   {keys[2]}/{keys[3]} elbow   space reset (-1)   "
                     f"tab hide arm   p pause   esc quit")
        screen.blit(self.text(help_line, small, FAINT), (x0, y0 + 40 * unit))
        bar_w, bar_h, gap = 150 * unit, 12 * unit, 6 * unit
        top = y0 + 68 * unit
        for i, (name, a) in enumerate(zip(self.muscle_names, session.muscles.activation, strict=True)):
            y = top + i * (bar_h + gap)
            label = self.text(f"{keys[i]}  {name}", small)
            screen.blit(label, (x0, y - 2 * unit))
            bx = x0 + 160 * unit
            pygame.draw.rect(screen, BAR_BACK, (bx, y, bar_w, bar_h))
            if a > 0.002:
                pygame.draw.rect(screen, MUSCLE_COLOURS[i], (bx, y, max(1.0, bar_w * min(a, 1.0)), bar_h))

    def _banner(self, screen: pygame.Surface, view: Viewport, title: str, subtitle: str) -> None:
        unit = view.scale / 500.0
        head = self.text(title, max(16, round(64 * unit)))
        sub = self.text(subtitle, max(10, round(26 * unit)), FAINT)
        cx, cy = screen.get_width() / 2, view.top + view.scale * 0.55
        panel = pygame.Rect(0, 0, max(head.get_width(), sub.get_width()) + 60 * unit, 130 * unit)
        panel.center = (round(cx), round(cy))
        pygame.draw.rect(screen, PANEL, panel, border_radius=round(10 * unit))
        pygame.draw.rect(screen, FAINT, panel, 2, border_radius=round(10 * unit))
        screen.blit(head, head.get_rect(center=(cx, cy - 22 * unit)))
        screen.blit(sub, sub.get_rect(center=(cx, cy + 32 * unit)))

    def _name_prompt(self, screen: pygame.Surface, view: Viewport, score: int, name: str) -> None:
        unit = view.scale / 500.0
        head = self.text(f"Your score: {score}", max(16, round(64 * unit)))
        ask = self.text("Type your name for the high-score table", max(10, round(26 * unit)))
        hint = self.text("Enter to save   -   Esc to quit without saving", max(10, round(22 * unit)), FAINT)
        font = self._font(max(12, round(40 * unit)))
        typed = font.render(name + "|", True, TEXT)  # not cached: it changes with every key
        box_w = max(font.size("M" * 16)[0], typed.get_width()) + 24 * unit
        cx, cy = screen.get_width() / 2, view.top + view.scale * 0.55
        panel = pygame.Rect(0, 0, max(head.get_width(), ask.get_width(), box_w) + 60 * unit, 250 * unit)
        panel.center = (round(cx), round(cy))
        pygame.draw.rect(screen, PANEL, panel, border_radius=round(10 * unit))
        pygame.draw.rect(screen, FAINT, panel, 2, border_radius=round(10 * unit))
        screen.blit(head, head.get_rect(center=(cx, cy - 80 * unit)))
        screen.blit(ask, ask.get_rect(center=(cx, cy - 28 * unit)))
        box = pygame.Rect(0, 0, box_w, font.get_height() + 12 * unit)
        box.center = (round(cx), round(cy + 25 * unit))
        pygame.draw.rect(screen, BACKGROUND, box, border_radius=round(4 * unit))
        pygame.draw.rect(screen, TEXT, box, 2, border_radius=round(4 * unit))
        screen.blit(typed, typed.get_rect(midleft=(box.left + 12 * unit, box.centery)))
        screen.blit(hint, hint.get_rect(center=(cx, cy + 85 * unit)))
