"""Text in any script: the names students type are drawn as the characters they are.

The windows' font (pygame's default, FreeSans Bold) draws Latin, Greek and Cyrillic, but a name in
Hebrew, Arabic, Chinese or Hindi would come out as empty boxes, and a right-to-left name with its
letters in the wrong order. ``TextRenderer`` is the game's renderer with one change: a string that
the default font cannot draw whole, or that holds right-to-left letters, is split into runs of one
direction, each drawn with the first font on this machine that has all of its glyphs (right-to-left
runs shaped right to left by SDL_ttf's HarfBuzz), and the runs are placed in visual order. An ASCII
string is measured and drawn exactly as the game's renderer does; any other is measured as one line
of the default font whatever its letters (an accented capital or a stack of combining marks never
makes a row taller), so a layout's rows stay where they were.

The runs follow a simplified Unicode bidirectional algorithm (UAX #9) for one line with no explicit
embeddings (the names that reach a window are checked printable, which leaves out the invisible
direction marks): letters set their run's direction, digits read left to right, spaces and
punctuation take the direction of the letters on both sides when those agree and the line's
otherwise, and the line's direction is its first letter's.
"""

from __future__ import annotations

import unicodedata
from functools import cache

import pygame

from .render import RGB, GameRenderer, Label, Palette

#: Fonts tried, in order, for what the default font lacks (pygame's names for installed fonts: lower
#: case, no spaces). The common ones on Linux, Windows and macOS with Hebrew, Arabic and more.
FALLBACK_FONTS = ("dejavusans", "notosans", "freesans", "notosanshebrew", "notosansarabic", "arial", "segoeui",
                  "tahoma", "arialunicodems", "liberationsans", "notosanscjksc", "notosanscjk", "droidsansfallback",
                  "wenquanyizenhei", "microsoftyahei", "msgothic", "notosansdevanagari", "nirmalaui", "mangal")
#: ISO 15924 script codes SDL_ttf shapes by: the first word of a letter's Unicode name to its script.
SCRIPTS = {"ARABIC": "Arab", "HEBREW": "Hebr", "SYRIAC": "Syrc", "THAANA": "Thaa", "NKO": "Nkoo",
           "DEVANAGARI": "Deva", "BENGALI": "Beng", "GURMUKHI": "Guru", "GUJARATI": "Gujr", "TAMIL": "Taml",
           "TELUGU": "Telu", "KANNADA": "Knda", "MALAYALAM": "Mlym", "THAI": "Thai", "KHMER": "Khmr"}
_RTL = ("R", "AL")
_NUMBER = ("EN", "AN")
#: How far accents may rise above a line of text, as a fraction of its height (into the gap above it).
HEADROOM = 0.2
#: Caches kept bounded: a window that runs for a lesson sees new names all the time.
MAX_CACHED = 2048


def _kind(c: str) -> str:
    """'L' or 'R' (a letter's direction), 'N' (a digit) or 'O' (a space, punctuation, a mark)."""
    bidi = unicodedata.bidirectional(c)
    if bidi in _RTL:
        return "R"
    if bidi == "L":
        return "L"
    return "N" if bidi in _NUMBER else "O"


def has_rtl(text: str) -> bool:
    return any(unicodedata.bidirectional(c) in _RTL for c in text)


def visual_runs(text: str) -> list[tuple[str, bool]]:
    """``text`` as runs of one direction, left to right as they are shown: (the run's characters in
    reading order, whether it reads right to left).

    >>> visual_runs("Ann 2")
    [('Ann 2', False)]
    >>> visual_runs("שלום 12")
    [('12', False), ('שלום ', True)]
    >>> visual_runs("Dee ודן")
    [('Dee ', False), ('ודן', True)]
    """
    if not text:
        return []
    kinds = [_kind(c) for c in text]
    rtl_base = next((k == "R" for k in kinds if k in "LR"), False)
    base = 1 if rtl_base else 0
    left_level = 2 if rtl_base else 0
    levels: list[int | None] = []
    strong = "R" if rtl_base else "L"
    for k in kinds:
        if k in "LR":
            strong = k
            levels.append(left_level if k == "L" else 1)
        elif k == "N":  # digits after right-to-left letters read left to right inside them
            levels.append(2 if strong == "R" else left_level)
        else:
            levels.append(None)
    # Spaces and punctuation: the direction of both neighbours (a digit counts as right to left) when
    # they agree, else the line's; the line's ends count as the line's direction.
    side = ["R" if k == "N" else k for k in kinds]
    i = 0
    while i < len(text):
        if levels[i] is not None:
            i += 1
            continue
        j = i
        while j < len(text) and levels[j] is None:
            j += 1
        before = side[i - 1] if i > 0 else ("R" if rtl_base else "L")
        after = side[j] if j < len(text) else ("R" if rtl_base else "L")
        level = (1 if before == "R" else left_level) if before == after else base
        for n in range(i, j):
            levels[n] = level
        i = j
    runs: list[list] = []
    for c, level in zip(text, levels, strict=True):
        if runs and runs[-1][1] == level:
            runs[-1][0] += c
        else:
            runs.append([c, level])
    # Reverse every stretch of runs at each level and above, from the highest level down to 1.
    top = max(level for _, level in runs)
    for level in range(top, 0, -1):
        i = 0
        while i < len(runs):
            if runs[i][1] >= level:
                j = i
                while j < len(runs) and runs[j][1] >= level:
                    j += 1
                runs[i:j] = runs[i:j][::-1]
                i = j
            else:
                i += 1
    return [(chars, level % 2 == 1) for chars, level in runs]


def script_of(text: str) -> str | None:
    """The ISO 15924 code of the first letter's script that SDL_ttf must be told to shape it (None: Latin
    and the rest, which need no shaping)."""
    for c in text:
        if unicodedata.bidirectional(c) in ("L", *_RTL):
            return SCRIPTS.get(unicodedata.name(c, "").split(" ")[0])
    return None


@cache
def _fallback_paths() -> tuple[str, ...]:
    """The fallback fonts installed here, bold where there is a bold (the windows' font is), asking the
    system's font list once: only when a string needs it."""
    found: list[str] = []
    for name in FALLBACK_FONTS:
        try:
            path = pygame.font.match_font(name, bold=True)
        except (OSError, ValueError):  # a broken font list is no reason to fail a window
            path = None
        if path and path not in found:
            found.append(path)
    return tuple(found)


class _Coverage:
    """Which characters each font has a glyph for (pygame.freetype tells a missing glyph apart)."""

    def __init__(self) -> None:
        self._fonts: dict[str | None, object] = {}
        self._known: dict[tuple[str | None, str], bool] = {}

    def covers(self, path: str | None, text: str) -> bool:
        missing = [c for c in set(text) if not c.isspace() and (path, c) not in self._known]
        if missing:
            font = self._font(path)
            metrics = font.get_metrics("".join(missing)) if font is not None else [()] * len(missing)
            if len(self._known) > 8 * MAX_CACHED:
                self._known.clear()
            for c, m in zip(missing, metrics, strict=False):
                self._known[(path, c)] = m is not None
        return all(self._known.get((path, c), True) for c in text if not c.isspace())

    def _font(self, path: str | None) -> object:
        if path not in self._fonts:
            try:
                import pygame.freetype

                pygame.freetype.init()
                self._fonts[path] = pygame.freetype.Font(path, 16)
            except (ImportError, OSError, pygame.error):  # no freetype module: trust the default font
                self._fonts[path] = None
        return self._fonts[path]


class TextRenderer(GameRenderer):
    """The game's renderer, drawing any printable Unicode (see the module).

    An ASCII string is measured and drawn as the game's renderer does. Any other is measured as one
    line of the default font (``text_size``: the same height whatever its letters, so a row of names
    stays a row), and drawn by ``draw_label`` on that line's baseline: accents above a capital may
    rise into the gap above the line by up to HEADROOM of its height, and nothing reaches further (a
    name stacked with combining marks stays in its row)."""

    def __init__(self, key_labels: tuple[str, ...] = (), muscle_names: tuple[str, ...] = (),
                 palette: str | Palette = "okabe-ito", text_scale: float = 1.0) -> None:
        super().__init__(key_labels, muscle_names, palette, text_scale)
        self._coverage = _Coverage()
        self._plain: dict[str, bool] = {}
        self._run_fonts: dict[tuple[str | None, int, bool, str | None], pygame.font.Font] = {}
        self._lifted: dict[tuple[str, int, RGB], tuple[pygame.Surface, int]] = {}

    def is_plain(self, text: str) -> bool:
        """Whether the default font draws ``text`` as it is: left to right, a glyph for every letter."""
        if text.isascii():
            return True
        plain = self._plain.get(text)
        if plain is None:
            if len(self._plain) > MAX_CACHED:
                self._plain.clear()
            plain = self._plain[text] = not has_rtl(text) and self._coverage.covers(None, text)
        return plain

    def _path_for(self, run: str) -> str | None:
        """The first font that has every glyph of ``run``: the default font, else a fallback (none has
        them all: the default's boxes)."""
        if self._coverage.covers(None, run):
            return None
        return next((path for path in _fallback_paths() if self._coverage.covers(path, run)), None)

    def _run_font(self, path: str | None, height: int, rtl: bool, script: str | None) -> pygame.font.Font:
        key = (path, height, rtl, script)
        font = self._run_fonts.get(key)
        if font is None:
            if path is None and not rtl and script is None:
                font = self.font(height)
            else:
                font = _matched(path, self.font(height))
                if _has_harfbuzz():  # without it, _pieces reverses right-to-left runs by hand
                    if rtl:
                        font.set_direction(pygame.DIRECTION_RTL)
                    if script is not None:
                        font.set_script(script)
            if len(self._run_fonts) > 256:
                self._run_fonts.clear()
            self._run_fonts[key] = font
        return font

    def _pieces(self, text: str, height: int) -> list[tuple[str, pygame.font.Font]]:
        if self.is_plain(text):
            return [(text, self.font(height))]
        pieces = []
        for run, rtl in visual_runs(text):
            font = self._run_font(self._path_for(run), height, rtl, script_of(run))
            # Where the font cannot shape right to left, the characters go in reverse (Hebrew reads
            # right; Arabic's letters stay unjoined).
            if rtl and not _has_harfbuzz():
                run = run[::-1]
            pieces.append((run, font))
        return pieces

    def text_size(self, text: str, height: int) -> tuple[int, int]:
        if text.isascii():
            return super().text_size(text, height)
        key = (text, height)
        size = self._sizes.get(key)
        if size is None:
            width = sum(font.size(run)[0] for run, font in self._pieces(text, height))
            size = (width, self.font(height).get_height())
            if len(self._sizes) > 2048:
                self._sizes.clear()
            self._sizes[key] = size
        return size

    def rendered(self, text: str, height: int, colour: RGB | None = None) -> tuple[pygame.Surface, int]:
        """``text`` drawn, and how many pixels above its label's rectangle the surface goes."""
        colour = self.palette.ink if colour is None else colour
        if text.isascii():
            return super().text(text, height, colour), 0
        key = (text, height, colour)
        done = self._lifted.get(key)
        if done is None:
            line = self.font(height)
            room = round(HEADROOM * line.get_height())
            pieces = [(font.render(run, True, colour), font, run) for run, font in self._pieces(text, height)]
            out = pygame.Surface((max(1, sum(s.get_width() for s, _, _ in pieces)), line.get_height() + room),
                                 pygame.SRCALPHA)
            x = 0
            for surface, font, run in pieces:
                out.blit(surface, (x, room + line.get_ascent() - _baseline(font, run)))
                x += surface.get_width()
            if len(self._lifted) > 512:
                self._lifted.clear()
            done = self._lifted[key] = (out, room)
        return done

    def text(self, string: str, height: int, colour: RGB | None = None) -> pygame.Surface:
        """The surface ``draw_label`` draws (taller than the label's rectangle for any non-ASCII string)."""
        return self.rendered(string, height, colour)[0]

    def fit_tail(self, text: str, height: int, width: int) -> str:
        """``text`` cut at its start with an ellipsis to ``width`` px (what is typed: its end stays in view)."""
        if self.text_size(text, height)[0] <= width:
            return text
        while text and self.text_size("..." + text, height)[0] > width:
            text = text[1:]
        return "..." + text

    def draw_label(self, screen: pygame.Surface, label: Label) -> pygame.Rect:
        surface, lift = self.rendered(label.text, label.height, label.colour)
        return screen.blit(surface, (label.rect.x, label.rect.y - lift))


def _baseline(font: pygame.font.Font, run: str) -> int:
    """Where SDL_ttf puts the baseline in a surface it renders: at the font's ascent, lower when a glyph
    (an accented capital) rises above it."""
    tops = [m[3] for m in font.metrics(run) if m]
    return max([font.get_ascent(), *tops])


def _cap_height(font: pygame.font.Font) -> int:
    metrics = font.metrics("H")
    return metrics[0][3] if metrics and metrics[0] else font.get_ascent()


def _matched(path: str | None, reference: pygame.font.Font) -> pygame.font.Font:
    """The font at ``path`` at the smallest size whose capitals are as tall as ``reference``'s: its letters
    look as large beside the default font's (fonts differ in how much of their line the letters fill)."""
    target = _cap_height(reference)
    size = max(1, round(reference.get_point_size() * 0.8))
    font = pygame.font.Font(path, size)
    while _cap_height(font) < target and size < 4 * reference.get_point_size():
        size += 1
        font = pygame.font.Font(path, size)
    return font


@cache
def _has_harfbuzz() -> bool:
    """Whether SDL_ttf shapes text here (pygame-ce built with HarfBuzz: right to left, joined letters)."""
    try:
        pygame.font.Font(None, 10).set_direction(pygame.DIRECTION_RTL)
    except (AttributeError, pygame.error):
        return False
    return True
