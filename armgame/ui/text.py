"""The windows' text kit: fonts, rendered text and measures, cached, under one sizing rule.

Every window sizes its text by line height in pixels (a projector's back row reads heights, not point
sizes) and measures, cuts and wraps it the same way: ``TextKit``. A kit is made with the rule that turns a
height into pygame's nominal font size, and there are two, kept apart so that no window's picture moved
when they came together here (the looks tests hold the pixels):

* ``line_height_size``: the game's renderer's (and so the lab's, the autopilot's and the class's): the
  default font's lines are about 0.68 of its nominal size, and never shorter than asked;
* ``smallest_size``: the demo windows': the smallest nominal size whose lines are the height or more.

Rendered surfaces (512) and measures (2,048) are cached: the clock and the speeds make new strings every
frame, and a layout measures the same strings frame after frame.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import pygame

from .palette import RGB


def line_height_size(height: int, font: Callable[[int], pygame.font.Font]) -> int:
    """The renderer's rule: pygame's default font renders lines about 0.68 times its nominal size high; the
    size that makes lines of ``height`` px, never shorter (``font``: the kit's font of a nominal size)."""
    size = max(1, round(height / 0.68))
    while font(size).get_height() < height and size < 4 * height:
        size += 1
    return size


def smallest_size(height: int, font: Callable[[int], pygame.font.Font]) -> int:
    """The demos' rule: the smallest nominal size whose lines are ``height`` px or more."""
    size = max(1, round(height / 0.7))
    while size > 1 and font(size - 1).get_height() >= height:
        size -= 1
    while font(size).get_height() < height:
        size += 1
    return size


@dataclass(frozen=True)
class Label:
    """One text placed: what it says, the line height asked for (the rect has the font's real one), its
    colour, its rectangle and its role (the tests name overlapping texts by it)."""

    text: str
    height: int
    colour: RGB
    rect: pygame.Rect
    role: str


class TextKit:
    """Fonts by line height (``font``), text drawn (``text``) and measured (``text_size``), cut to a width
    (``fit_text``) and wrapped (``wrap_text`` between words, ``wrap_items`` between whole items).

    ``ink`` is the colour of text drawn without one (``default_colour``); ``rule`` is the sizing rule
    (``line_height_size`` or ``smallest_size``)."""

    def __init__(self, ink: RGB = (0, 0, 0),
                 rule: Callable[[int, Callable[[int], pygame.font.Font]], int] = line_height_size) -> None:
        self._ink = ink
        self.rule = rule
        self._by_size: dict[int, pygame.font.Font] = {}
        self._nominal: dict[int, int] = {}
        self._rendered: dict[tuple[str, int, RGB], pygame.Surface] = {}
        self._sizes: dict[tuple[str, int], tuple[int, int]] = {}

    def _font_of_size(self, size: int) -> pygame.font.Font:
        font = self._by_size.get(size)
        if font is None:
            font = self._by_size[size] = pygame.font.Font(None, size)
        return font

    def default_colour(self) -> RGB:
        """The colour of text drawn without one (a renderer's: its palette's ink, whichever is on now)."""
        return self._ink

    def nominal(self, height: int) -> int:
        """The nominal size the rule gives lines of ``height`` px (the demos scale their spacing by it)."""
        size = self._nominal.get(height)
        if size is None:
            size = self._nominal[height] = self.rule(height, self._font_of_size)
        return size

    def font(self, height: int) -> pygame.font.Font:
        """pygame's default font for lines of ``height`` px, by the kit's rule (made once per size)."""
        return self._font_of_size(self.nominal(height))

    def text(self, string: str, height: int, colour: RGB | None = None) -> pygame.Surface:
        """``string`` drawn at ``height`` in ``colour`` (default ``default_colour()``), antialiased."""
        colour = self.default_colour() if colour is None else colour
        key = (string, height, colour)
        surface = self._rendered.get(key)
        if surface is None:
            if len(self._rendered) > 512:  # the clock makes new strings every frame
                self._rendered.clear()
            surface = self._rendered[key] = self.font(height).render(string, True, colour)
        return surface

    def text_size(self, text: str, height: int) -> tuple[int, int]:
        """``Font.size``, remembered: a layout measures the same strings frame after frame."""
        key = (text, height)
        size = self._sizes.get(key)
        if size is None:
            if len(self._sizes) > 2048:
                self._sizes.clear()
            size = self._sizes[key] = self.font(height).size(text)
        return size

    def label(self, text: str, height: int, colour: RGB, role: str, **anchor: object) -> Label:
        """A ``Label`` of ``text`` placed by ``anchor`` (``topleft=(x, y)``, ``midbottom=...``)."""
        w, h = self.text_size(text, height)
        rect = pygame.Rect(0, 0, w, h)
        for name, value in anchor.items():
            setattr(rect, name, value)
        return Label(text, height, colour, rect, role)

    def fit_text(self, text: str, height: int, width: int) -> str:
        """``text`` cut with an ellipsis to ``width`` px (a long name in the table)."""
        if self.text_size(text, height)[0] <= width:
            return text
        while text and self.text_size(text + "...", height)[0] > width:
            text = text[:-1]
        return text + "..."

    def wrap_text(self, text: str, height: int, width: int, max_lines: int | None = 3, fit: bool = True) -> list[str]:
        """``text`` on as many lines of ``width`` px as it needs, broken between words, at most ``max_lines``
        (None: any number; the last cut with an ellipsis only if even those do not hold it): a message is read
        whole, not cut off. ``fit``: a line still too wide (one long word) is cut with an ellipsis."""
        lines: list[str] = []
        for word in text.split():
            if lines and self.text_size(lines[-1] + " " + word, height)[0] <= width:
                lines[-1] += " " + word
            else:
                lines.append(word)
        if max_lines is not None and len(lines) > max_lines:
            lines = [*lines[:max_lines - 1], " ".join(lines[max_lines - 1:])]
        return [self.fit_text(line, height, width) for line in lines] if fit else lines

    def wrap_items(self, items: Sequence[str], height: int, width: int, gap: int = 0, *, sep: str = " " * 4,
                   fit: bool = True) -> list[str]:
        """Items (help keys, a status's parts) on as few lines as fit ``width``, ``sep`` apart; an item is
        never split (``fit``: one too wide alone is cut with an ellipsis). ``gap`` is unused (the callers'
        spacing between lines)."""
        lines: list[str] = []
        for item in items:
            if fit:
                item = self.fit_text(item, height, width)
            if lines and self.text_size(lines[-1] + sep + item, height)[0] <= width:
                lines[-1] += sep + item
            else:
                lines.append(item)
        return lines
