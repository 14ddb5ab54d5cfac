"""What the lab window draws between and after trials: cards, a reach's path, the learning curve.

Drawn with pygame alone (no matplotlib: a class's machines may not have it), at the window's text
sizes (``render.text_heights``), so the smallest text is legible at the back of a room. Each
function returns the rectangles of the text it placed, for the tests' overlap and size checks.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
import pygame

from ..lab.analysis import LearningCurve
from .body import blend
from .render import MIN_LINE, RGB, Viewport, text_heights

if TYPE_CHECKING:
    from ..lab.session import LabSession, TrialOutcome
    from .render import GameRenderer

Placed = list[tuple[str, pygame.Rect]]


def _wrap(renderer: GameRenderer, text: str, height: int, width: int) -> list[str]:
    lines: list[str] = []
    for word in text.split():
        if lines and renderer.text_size(lines[-1] + " " + word, height)[0] <= width:
            lines[-1] += " " + word
        else:
            lines.append(renderer.fit_text(word, height, width))
    return lines


def _blit(renderer: GameRenderer, screen: pygame.Surface, placed: Placed, text: str, height: int, colour: RGB,
          **anchor: tuple[int, int]) -> pygame.Rect:
    surface = renderer.text(text, height, colour)
    rect = surface.get_rect(**anchor)
    screen.blit(surface, rect)
    placed.append((text, rect))
    return rect


def _panel(renderer: GameRenderer, screen: pygame.Surface, rect: pygame.Rect, radius: int) -> None:
    p = renderer.palette
    pygame.draw.rect(screen, p.panel, rect, border_radius=radius)
    pygame.draw.rect(screen, p.edge, rect, max(3, radius // 4), border_radius=radius)


def draw_card(renderer: GameRenderer, screen: pygame.Surface, title: str, lines: Sequence[str],
              prompt: str) -> Placed:
    """A card over the scene: a title, what to do, and the key that goes on."""
    p = renderer.palette
    w, h = screen.get_size()
    big, normal, small = text_heights((w, h), renderer.text_scale)
    pad = normal
    width = min(w - 2 * small, max(round(w * 0.7), 40 * small))
    inner = width - 2 * pad
    wrapped = [_wrap(renderer, line, normal, inner) for line in lines]
    line_h = renderer.font(normal).get_height()
    height = renderer.font(big).get_height() + pad + sum(len(x) * line_h + pad // 3 for x in wrapped) + \
        pad + renderer.font(normal).get_height() + 2 * pad
    rect = pygame.Rect(0, 0, width, min(height, h - 2 * small))
    rect.center = (w // 2, h // 2)
    _panel(renderer, screen, rect, pad // 2)
    placed: Placed = []
    y = _blit(renderer, screen, placed, renderer.fit_text(title, big, inner), big, p.ink,
              midtop=(rect.centerx, rect.top + pad)).bottom + pad
    for paragraph in wrapped:
        for line in paragraph:
            y = _blit(renderer, screen, placed, line, normal, p.ink, topleft=(rect.left + pad, y)).bottom
        y += pad // 3
    _blit(renderer, screen, placed, prompt, normal, p.warn, midbottom=(rect.centerx, rect.bottom - pad))
    return placed


def draw_feedback(renderer: GameRenderer, screen: pygame.Surface, view: Viewport, session: LabSession,
                  outcome: TrialOutcome) -> None:
    """Knowledge of results: the straight line asked for and the path made (its measure is in the HUD). As the trial
    gives it (issue 41): with ``endpoint`` feedback only where the reach ended, with ``none`` nothing."""
    p = renderer.palette
    w, h = screen.get_size()
    width = max(MIN_LINE, round(min(w, h) / 200))
    if outcome.plan.feedback == "none":
        return
    home = view.to_screen(*outcome.plan.home)
    target = view.to_screen(*outcome.plan.position)
    pygame.draw.line(screen, p.edge, home, target, width)
    pygame.draw.circle(screen, p.target, target, view.length(session.protocol.target_radius), width)
    n = outcome.reach_samples  # the reach, not the jump home after space
    if outcome.plan.feedback == "endpoint":
        if n:
            end = view.to_screen(outcome.xs[n - 1], outcome.ys[n - 1])
            pygame.draw.circle(screen, p.hand, end, max(width + 1, view.length(0.006)))
        return
    points = [view.to_screen(x, y) for x, y in zip(outcome.xs[:n:4], outcome.ys[:n:4], strict=True)]
    if len(points) > 1:
        pygame.draw.lines(screen, p.trail, False, points, width)
        for end in (points[0], points[-1]):
            pygame.draw.circle(screen, p.trail, end, width // 2)
    pygame.draw.circle(screen, p.hand, points[-1] if points else home, max(width + 1, view.length(0.006)))


def _ticks(low: float, high: float) -> list[float]:
    span = high - low
    if not span > 0:
        return [low]
    raw = span / 4.0
    magnitude = 10.0 ** math.floor(math.log10(raw))
    step = next(m * magnitude for m in (1.0, 2.0, 2.5, 5.0, 10.0) if m * magnitude >= raw)
    first = math.ceil(low / step) * step
    return [round(first + k * step, 10) for k in range(int((high - first) / step + 1e-9) + 1)]


def draw_curve(renderer: GameRenderer, screen: pygame.Surface, rect: pygame.Rect, curve: LearningCurve,
               placed: Placed) -> None:
    """The learning curve in ``rect``: blocks shaded and named, a point per trial, each block's mean, the
    after-effect marked."""
    p = renderer.palette
    small = text_heights(screen.get_size(), renderer.text_scale)[2]
    points = curve.points
    if not points:
        return
    values = np.array([v for _, v, _ in points], dtype=float)
    finite = values[np.isfinite(values)]
    low, high = (min(float(finite.min()), 0.0), max(float(finite.max()), 0.0)) if finite.size else (-1.0, 1.0)
    margin = 0.08 * ((high - low) or 2.0)
    low, high = low - margin, high + margin
    ticks = _ticks(low, high)
    label_w = max(renderer.text_size(f"{t:g}", small)[0] for t in ticks) + small // 2
    head = renderer.font(small).get_height() + small // 3
    plot = pygame.Rect(rect.left + label_w, rect.top + head, rect.width - label_w,
                       rect.height - head - renderer.font(small).get_height() - small // 3)
    last = max(t for t, _, _ in points)
    first = min(b.first for b in curve.blocks)
    total = max(b.last for b in curve.blocks)
    span = max(total - first + 1, 1)

    def x_of(trial: float) -> int:
        return round(plot.left + (trial - first + 0.5) / span * plot.width)

    def y_of(value: float) -> int:
        return round(plot.bottom - (value - low) / (high - low) * plot.height)

    line = max(3, round(small / 7))
    for i, block in enumerate(curve.blocks):
        shade = blend(p.panel, p.target if block.perturbed else p.link,
                      0.16 if block.perturbed else 0.07 + 0.04 * (i % 2))
        area = pygame.Rect(x_of(block.first - 0.5), plot.top, x_of(block.last + 0.5) - x_of(block.first - 0.5),
                           plot.height)
        pygame.draw.rect(screen, shade, area)
        name = renderer.fit_text(block.name, small, max(area.width - 4, 1))
        if name != "...":
            _blit(renderer, screen, placed, name, small, p.ink, midbottom=(area.centerx, plot.top - 2))
        if math.isfinite(block.mean) and low <= block.mean <= high:
            mean_y = y_of(block.mean)
            pygame.draw.line(screen, p.warn, (area.left + line, mean_y), (area.right - line, mean_y), line)
    for t in ticks:
        y = y_of(t)
        pygame.draw.line(screen, p.edge, (plot.left - line, y), (plot.left, y), 2)
        _blit(renderer, screen, placed, f"{t:g}", small, p.ink, midright=(plot.left - line - 2, y))
    pygame.draw.line(screen, p.edge, (plot.left, y_of(0.0)), (plot.right, y_of(0.0)), 2)
    pygame.draw.rect(screen, p.edge, plot, 2)
    radius = max(3, min(round(small / 4), round(plot.width / max(last, 1) / 2.2)))
    for trial, value, catch in points:
        if not math.isfinite(value):
            continue
        centre = (x_of(trial), y_of(value))
        if catch:
            pygame.draw.circle(screen, p.warn, centre, radius + 1, 2)
        else:
            pygame.draw.circle(screen, p.ink, centre, radius)
    if curve.after_effect is not None:
        trial, value = curve.after_effect
        centre = (x_of(trial), y_of(value))
        pygame.draw.circle(screen, p.warn, centre, radius + line + 2, line)
        # To the left, at the point's height (as the figure puts it): the perturbed block's points lie on
        # the other side of zero there, so the label sits in empty space, clear of the washout's mean line.
        width = renderer.text_size("after-effect", small)[0]
        gap = radius + line + small // 2
        if centre[0] - gap - width >= plot.left + 4:
            box = _blit(renderer, screen, placed, "after-effect", small, p.warn, midright=(centre[0] - gap, centre[1]))
            pygame.draw.line(screen, p.warn, (box.right + 2, centre[1]), (centre[0] - radius - line, centre[1]), 2)
        else:  # no room on the left (a protocol that starts with its washout): on the right
            _blit(renderer, screen, placed, "after-effect", small, p.warn, midleft=(centre[0] + gap, centre[1]))
    _blit(renderer, screen, placed, f"{curve.label} ({curve.unit}) by trial", small, p.ink,
          topleft=(plot.left, plot.bottom + small // 3))


def draw_end(renderer: GameRenderer, screen: pygame.Surface, summary: str, curve: LearningCurve,
             saved: Sequence[str], help_items: Sequence[str]) -> Placed:
    """The end of a run: what was done, the learning curve, each block's mean, and where the run was kept."""
    p = renderer.palette
    w, h = screen.get_size()
    big, normal, small = text_heights((w, h), renderer.text_scale)
    pad = small
    screen.fill(p.panel)
    placed: Placed = []
    y = _blit(renderer, screen, placed, renderer.fit_text(summary, big, w - 2 * pad), big, p.ink,
              midtop=(w // 2, pad)).bottom + pad // 2
    means = ",   ".join(f"{b.name} {b.mean:+.1f} {curve.unit}" if math.isfinite(b.mean) else f"{b.name} -"
                       for b in curve.blocks)
    mean_lines = _wrap(renderer, f"Block means: {means}", normal, w - 2 * pad)
    line_h = renderer.font(small).get_height()
    bottom_lines = len(saved) + 1
    bottom = h - pad - bottom_lines * (line_h + pad // 4) - len(mean_lines) * (renderer.font(normal).get_height())
    plot = pygame.Rect(pad, y, w - 2 * pad - small, max(bottom - y - pad, 4 * small))
    draw_curve(renderer, screen, plot, curve, placed)
    y = plot.bottom + pad // 2
    for line in mean_lines:
        y = _blit(renderer, screen, placed, line, normal, p.ink, midtop=(w // 2, y)).bottom
    y += pad // 4
    for line in saved:
        y = _blit(renderer, screen, placed, renderer.fit_text(line, small, w - 2 * pad), small, p.ink,
                  topleft=(pad, y)).bottom + pad // 4
    _blit(renderer, screen, placed, "    ".join(help_items) or "Esc quit", small, p.faint, bottomleft=(pad, h - pad))
    return placed
