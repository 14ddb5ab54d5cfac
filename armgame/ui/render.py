"""Drawing the game with pygame: the arm, the target, the HUD and the panels.

The renderer reads a session (and how far between two physics steps the frame falls) and a ``Hud``
(what the window wants said: the mode, the keys that work, pause, countdown, the end screen) and draws
one frame; it never changes the game. Every frame is first laid out (``GameRenderer.layout``: where
each piece of text, each bar and the scene go, for this window size) and then drawn, so tests check
the layout of every screen at every window size without looking at pixels: every text inside the
window, no two overlapping, none smaller than a projector can show.

Sizes follow the window: ``unit = min(width, height) / 720``, so the HUD text is 16 to 40 px at 720
lines and the same proportions on a 4K projector. Landscape windows put the HUD in a sidebar beside a
square scene, portrait and square ones in bands above and below it, so nothing is ever drawn over the
arm's workspace except the panels that say the game is paused or over.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import pygame

from ..game.session import GameSession
from ..physics.hand import hand_xy
from ..words import plural
from .body import blend, draw_arm, draw_torso
from .palette import PALETTES, RGB, Palette  # PALETTES read from here too: its home until it moved down
from .text import Label, TextKit  # Label read from here too: its home until the text kit came

#: Smallest text height at 720 lines, in pixels (a projector at the back of a classroom).
MIN_TEXT_AT_720 = 14
#: ... and never below this fraction of the window's height (19 px at 768 lines).
MIN_TEXT_FRACTION = 0.025
#: Lines a student must see (trails, paths, outlines) are at least this wide, in pixels.
MIN_LINE = 3
#: A hit's flash and "+1" last this long; the next target fades in over FADE_IN (seconds of game time).
FLASH_TIME, PLUS_ONE_TIME, FADE_IN = 0.35, 0.9, 0.3
WARN_SECONDS = 10.0


def relative_luminance(colour: Sequence[int]) -> float:
    """WCAG 2.1 relative luminance of an sRGB colour."""
    def channel(c: int) -> float:
        c = c / 255.0
        return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4

    r, g, b = (channel(c) for c in colour[:3])
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def contrast_ratio(a: Sequence[int], b: Sequence[int]) -> float:
    la, lb = sorted((relative_luminance(a), relative_luminance(b)), reverse=True)
    return (la + 0.05) / (lb + 0.05)


def min_text(size: tuple[int, int]) -> int:
    """The smallest text height a window of ``size`` may show, in pixels."""
    return max(round(MIN_TEXT_AT_720 * min(size) / 720), round(MIN_TEXT_FRACTION * size[1]))


def text_heights(size: tuple[int, int], text_scale: float = 1.0) -> tuple[int, int, int]:
    """Text heights (big, normal, small) for a window of ``size``, times the ``text_scale`` setting."""
    small = round(max(min_text(size), round(18 * min(size) / 720)) * text_scale)
    return round(small * 1.6), round(small * 1.2), small


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

    def origin(self) -> tuple[float, float]:
        """Where the world's (0, 0) is, in (fractional) pixels."""
        xmin, _, _, ymax = self.world
        return self.left - xmin * self.scale, self.top + ymax * self.scale

    def length(self, metres: float) -> int:
        return max(1, round(metres * self.scale))


@dataclass(frozen=True)
class Standing:
    """Where a finished game stands in the high-score table (from the command, never read here).

    ``list_name`` is the heading of the list the game went to (or would go to), as the scores layer
    names it: the ranked table, custom games, programs, practice. ``pending``: the game is not entered
    yet (its name is being typed): ``rank`` and ``entries`` say where it would stand, and its own row
    in ``top`` has an empty name, drawn as the name being typed. ``mine`` says which row of ``top`` is the
    player's own, the one drawn as theirs: equal scores share a place, so the place cannot say it.
    """

    rank: int | None  # None: the game was not entered
    entries: int
    top: tuple[tuple[int, str, int], ...]  # (rank, name, score), best first; the game's own row may follow
    list_name: str = "the ranked table"  # the list the game went to: ranked, practice, programs, custom games
    pending: bool = False
    #: A line shown instead of "Rank N of M" (a live class's: "Handed in: 3rd of 12 in the class").
    note: str | None = None
    #: Asked every frame while the standing is still on its way (a hand-in over the network): returns
    #: the standing to show once it has arrived, None until then. The window never waits for it.
    later: Callable[[], Standing | None] | None = None
    #: The line naming the file the game was saved to ("Saved as ann-b-game3.json"): the one to hand in.
    saved: str | None = None
    #: The index in ``top`` of the player's own row; None: none of them is (a pending standing's is its row
    #: with the empty name).
    mine: int | None = None

    @property
    def own_row(self) -> int | None:
        """The index in ``top`` of the row drawn as the player's, if any."""
        if self.mine is not None:
            return self.mine
        if self.pending:
            return next((i for i, row in enumerate(self.top) if row[1] == ""), None)
        return None


@dataclass
class Hud:
    """What the window wants shown beyond the game itself."""

    #: Whose game is shown when it is not the player's at the keys ("AUTOPILOT: model", "REPLAY"): the mode
    #: line starts with it, and the end screen names it and says "Score", not "Your score". None: the player's
    #: own game, whose mode line starts "PLAY".
    driver: str | None = None
    #: The rest of the mode line ("seed 10"; a replay's player and date), each part kept whole on a line.
    details: tuple[str, ...] = ()
    help: tuple[str, ...] = ()
    paused: bool = False
    countdown: int | None = None  # 3, 2, 1 before the clock starts
    name_entry: str | None = None  # the name being typed on the end screen
    name_limit: int = 24
    standing: Standing | None = None
    end_hint: str = "Esc quits"  # the end screen's keys
    ended: bool = False  # the end screen
    progress: tuple[float, float] | None = None  # a replay: seconds shown, seconds recorded
    speed: float | None = None
    hits: Sequence[tuple[float, float, float]] = ()  # recent hits: x, y (m) and age (s of game time)
    trail: Sequence[tuple[float, float]] = ()  # hand positions (m), oldest first

    @property
    def mode(self) -> tuple[str, ...]:
        """The mode line's parts, as shown: "PLAY" or whose game it is, then the details."""
        return (self.driver or "PLAY", *self.details)


@dataclass
class Layout:
    size: tuple[int, int]
    scene: pygame.Rect
    view: Viewport
    labels: list[Label] = field(default_factory=list)
    bars: list[tuple[pygame.Rect, int, float]] = field(default_factory=list)  # rect, muscle, activation
    panels: list[pygame.Rect] = field(default_factory=list)
    progress: tuple[pygame.Rect, float] | None = None
    name_box: pygame.Rect | None = None
    rules: list[tuple[int, int, int]] = field(default_factory=list)  # left, right, y: a table's heading line

    @property
    def unit(self) -> float:
        return min(self.size) / 720.0

    def boxes(self) -> list[tuple[str, pygame.Rect]]:
        """Every text and bar rectangle, for the tests' overlap check."""
        return [(f"{lab.role}: {lab.text}", lab.rect) for lab in self.labels] + \
            [(f"bar {i}", r) for r, i, _ in self.bars] + \
            ([("progress", self.progress[0])] if self.progress else [])


def _without_nested(rects: list[pygame.Rect]) -> list[pygame.Rect]:
    """The rectangles, less any inside another (the hand inside the arm's): each pixel restored once."""
    rects.sort(key=lambda r: r.width * r.height, reverse=True)
    kept: list[pygame.Rect] = []
    for r in rects:
        if r.collidelist(kept) < 0 or not any(k.contains(r) for k in kept):
            kept.append(r)
    return kept


def clock_text(seconds: float) -> str:
    """Seconds to a tenth under 100 s (a 60 s game counts 60.0, 59.9, ...), minutes and seconds above."""
    if seconds < 100:
        return f"{seconds:4.1f}"
    whole = math.ceil(seconds)
    return f"{whole // 60}:{whole % 60:02d}"


class GameRenderer(TextKit):
    """Lays out and draws frames; fonts, text and the static background are made once and cached.

    Its text is the windows' text kit (``ui.text.TextKit``, the line-height rule), so the lab's, the
    autopilot's and the class's windows, which draw through a renderer, measure and wrap as the game does."""

    def __init__(self, key_labels: tuple[str, ...], muscle_names: tuple[str, ...],
                 palette: str | Palette = "okabe-ito", text_scale: float = 1.0) -> None:
        self.key_labels = key_labels
        #: The ``text_scale`` setting: every text this many times its usual size (a large room).
        self.text_scale = text_scale
        self.muscle_names = muscle_names
        self.palette = PALETTES[palette] if isinstance(palette, str) else palette
        super().__init__()
        self._backgrounds: dict[tuple, pygame.Surface] = {}
        self._veils: dict[tuple[int, int], pygame.Surface] = {}
        #: Where the last frame drew over its background (None: draw the next frame whole).
        self._dirty: list[pygame.Rect] | None = None
        self._frame_key: tuple | None = None
        #: The size of the window the text is read in, when this renderer draws only part of it (the
        #: autopilot's two games): text sized for the whole window, as the back row sees it. None: the
        #: surface drawn on is the window.
        self.text_basis: tuple[int, int] | None = None

    # ------------------------------------------------------------------ text
    def default_colour(self) -> RGB:
        return self.palette.ink

    def draw_label(self, screen: pygame.Surface, label: Label) -> pygame.Rect:
        """One label, in the default font (``names.TextRenderer`` draws any script)."""
        if label.role == "name":  # changes with every key: not worth caching
            return screen.blit(self.font(label.height).render(label.text, True, label.colour), label.rect)
        return screen.blit(self.text(label.text, label.height, label.colour), label.rect)

    # ---------------------------------------------------------------- layout
    def layout(self, size: tuple[int, int], session: GameSession, hud: Hud | None = None) -> Layout:
        """Where everything goes in a window of ``size``: pure geometry, nothing drawn."""
        hud = hud or Hud()
        w, h = size
        u = min(w, h) / 720.0
        pad, gap = max(6, round(16 * u)), max(4, round(8 * u))
        k = self.text_scale
        basis = self.text_basis or size
        tu = min(basis) / 720.0
        small = round(max(12, round(18 * tu), min_text(basis)) * k)
        normal = max(round(max(13, round(22 * tu)) * k), small + 2)
        big = round(max(18, round(40 * tu)) * k)
        p = self.palette
        landscape = w >= 1.15 * h
        if landscape:
            # Wide enough for the mode's words and the clock where the window allows (text sized for a
            # larger window than this one: a half of the autopilot's).
            needed = max([self.text_size(part, normal)[0] for part in hud.mode] +
                         [self.text_size("Time 00.0", big)[0]]) + 2 * pad
            side = min(max(round(w * 0.27), 200, needed), max(480, needed), w - round(h * 0.55))
            hud_area = pygame.Rect(pad, pad, side - 2 * pad, h - 2 * pad)
            scene = pygame.Rect(side, pad, w - side - pad, h - 2 * pad)
        else:
            hud_area = pygame.Rect(pad, pad, w - 2 * pad, h - 2 * pad)
            scene = pygame.Rect(pad, 0, w - 2 * pad, 0)  # top and height set below, between the bands
        labels: list[Label] = []
        bars: list[tuple[pygame.Rect, int, float]] = []
        board = session.rules.board
        x0, y = hud_area.left, hud_area.top
        # The mode, score and clock.
        # The mode's parts ("REPLAY", the player, the date) share a line where they fit.
        for line in self.wrap_items(hud.mode, normal, hud_area.width, gap):
            labels.append(self.label(line, normal, p.ink, "mode", topleft=(x0, y)))
            y = labels[-1].rect.bottom + gap // 2
        y += gap // 2
        # Score and clock share a line on a tall window: smaller than ``big`` where a narrow one (half of
        # the autopilot's) would make them meet, never smaller than ``normal``.
        head = big
        while not landscape and head > normal and \
                self.text_size("Score 000", head)[0] + 2 * gap + self.text_size("Time 00.0", head)[0] > hud_area.width:
            head -= 1
        score = self.label(f"Score {board.score}", head, p.ink, "score", topleft=(x0, y))
        clock_colour = p.warn if 0 < session.time_left <= WARN_SECONDS else p.ink
        clock = f"Time {clock_text(session.time_left)}"
        if landscape:
            labels.append(score)
            y = score.rect.bottom + gap
            labels.append(self.label(clock, head, clock_colour, "clock", topleft=(x0, y)))
        else:
            labels.append(score)
            # Right-aligned, but sized for the widest clock so it never moves as the digits change.
            widest = self.text_size("Time 00.0", head)[0]
            labels.append(self.label(clock, head, clock_colour, "clock",
                                     topleft=(hud_area.right - widest, y)))
        y = labels[-1].rect.bottom + 2 * gap
        # The replay's progress and speed.
        progress = None
        if hud.progress is not None:
            shown, total = hud.progress
            speed = f"   {hud.speed:g}x" if hud.speed is not None else ""
            text = self.fit_text(f"{clock_text(shown).strip()} of {clock_text(total).strip()} s{speed}", small,
                                 hud_area.width)
            labels.append(self.label(text, small, p.ink, "progress", topleft=(x0, y)))
            y = labels[-1].rect.bottom + gap // 2
            progress = (pygame.Rect(x0, y, hud_area.width, max(4, round(8 * u))),
                        min(max(shown / total, 0.0), 1.0) if total > 0 else 1.0)
            y = progress[0].bottom + 2 * gap
        # The muscle bars, or the pause panel in their place (the keys are released while paused).
        block_top = y
        columns = 1 if landscape else 2
        col_w = (hud_area.width - (columns - 1) * 2 * pad) // columns
        bar_h = max(5, round(10 * u))
        row_h = self.font(small).get_height() + gap // 2 + bar_h + gap
        block_h = row_h * (4 // columns)
        if hud.paused and not hud.ended:
            panel_labels = [self.label("PAUSED", big, p.ink, "pause", topleft=(x0, block_top)),
                            self.label("p to play on", small, p.faint, "pause", topleft=(x0, 0))]
            panel_labels[1].rect.top = panel_labels[0].rect.bottom + gap // 2
            labels += panel_labels
            block_h = max(block_h, panel_labels[1].rect.bottom - block_top)
        else:
            activation = session.muscles.activation
            # A column too narrow for "f  posterior deltoid" names each muscle by its last word ("deltoid").
            short = any(self.text_size(f"{key}  {name}", small)[0] > col_w
                        for key, name in zip(self.key_labels, self.muscle_names, strict=True))
            for i, (key, name) in enumerate(zip(self.key_labels, self.muscle_names, strict=True)):
                cx = x0 + (i % columns) * (col_w + 2 * pad)
                ry = block_top + (i // columns) * row_h
                name = name.split()[-1] if short and name.split() else name
                label = self.label(self.fit_text(f"{key}  {name}", small, col_w), small, p.ink, "muscle",
                                   topleft=(cx, ry))
                labels.append(label)
                bars.append((pygame.Rect(cx, label.rect.bottom + gap // 2, col_w, bar_h), i,
                             min(max(activation[i], 0.0), 1.0)))
        y = block_top + block_h + gap
        # The help line(s), at the bottom.
        help_lines = self.wrap_items(hud.help, small, hud_area.width, gap)
        line_h = self.font(small).get_height()
        bottom = hud_area.bottom
        for i, line in enumerate(reversed(help_lines)):
            anchor = {"bottomleft": (x0, bottom - i * (line_h + gap // 2))} if landscape else \
                {"midbottom": (w // 2, bottom - i * (line_h + gap // 2))}
            labels.append(self.label(line, small, p.faint, "help", **anchor))
        help_top = min((lab.rect.top for lab in labels if lab.role == "help"), default=bottom)
        if not landscape:
            scene.top = y
            scene.height = max(help_top - gap - y, 10)
        view = Viewport.fit(scene.size, session.config.view)
        view = Viewport(view.left + scene.left, view.top + scene.top, view.scale, view.world)
        lay = Layout(size, scene, view, labels, bars, [], progress)
        self._scene_labels(lay, session, hud, big, normal, small, gap)
        return lay

    def _scene_labels(self, lay: Layout, session: GameSession, hud: Hud, big: int, normal: int, small: int,
                      gap: int) -> None:
        """What is written over the scene: countdown, "+1"s and the end panel."""
        p = self.palette
        scene, view = lay.scene, lay.view
        if hud.countdown is not None and not hud.ended:
            size = max(big, round(scene.height * 0.2))
            number = self.label(str(hud.countdown), size, p.ink, "countdown", center=scene.center)
            hint = self.label("any key starts", normal, p.ink, "countdown",
                              midtop=(scene.centerx, number.rect.bottom + gap))
            lay.labels += [number, hint]
            # On a card of its own: the number must not tangle with the arm drawn behind it.
            card = number.rect.union(hint.rect).inflate(6 * gap, 3 * gap)
            lay.panels.append(card.clamp(scene))
        for x, y, age in hud.hits:
            if age < PLUS_ONE_TIME:
                px, py = view.to_screen(x, y)
                r = view.length(session.config.target_radius)
                label = self.label("+1", big, p.ink, "effect",
                                   midleft=(px + r + gap, py - round(age / PLUS_ONE_TIME * 2 * r)))
                label.rect.clamp_ip(scene)
                lay.labels.append(label)
        if hud.ended:
            self._end_panel(lay, session, hud, big, normal, small, gap)

    def _end_panel(self, lay: Layout, session: GameSession, hud: Hud, big: int, normal: int, small: int,
                   gap: int) -> None:
        """The end screen, over the whole window (the game being over): the score, where it stands and
        the table's top under the list's heading, all at once; then the name box while a name is asked;
        then the keys. Rows of the table are left out from the bottom (never the game's own) if the
        window is too short for all of them."""
        p = self.palette
        w, h = lay.size
        # The HUD is hidden under the panel: only the panel's text is laid out.
        lay.labels = []
        lay.bars = []
        lay.progress = None
        board = session.rules.board
        playing = hud.driver is None
        lines: list[tuple[str, int, RGB]] = []
        if hud.driver is not None:  # whose game it was: a bot's, a replay's
            lines.append((hud.driver, normal, p.ink))
        lines += [(f"Your score: {board.score}" if playing else f"Score: {board.score}", big, p.ink),
                  (f"{plural(board.hits, 'hit')}, {plural(board.resets, 'reset')}", normal, p.ink)]
        standing = hud.standing
        rows: list[tuple[int, tuple[int, str, int]]] = []  # (index in standing.top, row)
        if standing is not None:
            if standing.note is not None:
                lines += [(part, normal, p.ink) for part in standing.note.split("\n")]
            elif standing.rank is not None:
                would = "You would rank" if standing.pending else "Rank"
                lines.append((f"{would} {standing.rank} of {standing.entries}", normal, p.ink))
            else:
                lines.append(("Not entered in the table", normal, p.ink))
            if standing.saved is not None:
                lines.append((standing.saved, normal, p.ink))
            rows = list(enumerate(standing.top))
        margin = max(8, round(24 * lay.unit))
        panel_w = min(w - 2 * margin, max(round(560 * lay.unit), 300))
        # A long line (the class's answer, "your game is kept ...") wraps in the panel rather than being cut off.
        lines = [(part, size, colour) for text, size, colour in lines
                 for part in self.wrap_text(text, size, panel_w - 2 * margin, max_lines=6)]
        heading = bool(rows) and standing is not None
        content_h = sum(self.font(size).get_height() + gap for _, size, _ in lines)
        if heading:
            content_h += self.font(normal).get_height() + 2 * gap
        if hud.name_entry is not None:
            content_h += self.font(small).get_height() + gap // 2 + self.font(normal).get_height() + 3 * gap
        content_h += self.font(small).get_height() + 2 * gap  # the hint
        room = h - 2 * margin - content_h - 2 * margin
        own = standing.own_row if standing is not None else None
        # The table in the size of the lines above it where it fits (the back row reads it), else smaller.
        row_size = normal if len(rows) * (self.font(normal).get_height() + gap // 2) <= room else small
        row_h = self.font(row_size).get_height() + gap // 2
        while rows and len(rows) * row_h > room:  # too short a window: the table's last rows go first
            drop = next((i for i in range(len(rows) - 1, -1, -1) if rows[i][0] != own), None)
            if drop is None:
                break
            del rows[drop]
        content_h += len(rows) * row_h
        panel = pygame.Rect(0, 0, panel_w, min(h - 2 * margin, content_h + 2 * margin))
        panel.center = (w // 2, h // 2)
        lay.panels.append(panel)
        inner = panel.inflate(-2 * margin, -2 * margin)
        y = inner.top
        for text, size, colour in lines:
            lab = self.label(self.fit_text(text, size, inner.width), size, colour, "end", midtop=(inner.centerx, y))
            lay.labels.append(lab)
            y = lab.rect.bottom + gap
        if heading:
            title = standing.list_name[:1].upper() + standing.list_name[1:]
            lab = self.label(self.fit_text(title, normal, inner.width), normal, p.ink, "heading",
                             midtop=(inner.centerx, y + gap))
            lay.labels.append(lab)
            lay.rules.append((inner.left, inner.right, lab.rect.bottom + gap // 2))
            y = lab.rect.bottom + gap
            cell = row_size
            rank_w = self.text_size("999.", cell)[0] + gap
            score_w = self.text_size("9999", cell)[0]
            name_w = inner.width - rank_w - score_w - 2 * gap
            for index, (rank, name, score) in rows:
                mine = index == own
                if mine and standing.pending:
                    name = hud.name_entry or "you"
                colour = p.warn if mine else p.ink
                lay.labels.append(self.label(f"{rank}.", cell, colour, "table",
                                             topright=(inner.left + rank_w - gap, y)))
                if name:
                    lay.labels.append(self.label(self.fit_text(name, cell, name_w), cell, colour, "table",
                                                 topleft=(inner.left + rank_w, y)))
                lay.labels.append(self.label(str(score), cell, colour, "table", topright=(inner.right, y)))
                y += row_h
        if hud.name_entry is not None:
            y += gap
            counter = f"{len(hud.name_entry)}/{hud.name_limit}"
            ask = self.label(self.fit_text("Type your name for the table", small,
                                           inner.width - self.text_size(counter, small)[0] - 2 * gap),
                             small, p.ink, "end", topleft=(inner.left, y))
            lay.labels.append(ask)
            # The length limit, visible as the name is typed (the box takes no more).
            lay.labels.append(self.label(counter, small, p.warn if len(hud.name_entry) >= hud.name_limit
                                         else p.faint, "counter", topright=(inner.right, y)))
            y = ask.rect.bottom + gap // 2
            box_h = self.font(normal).get_height() + 2 * gap
            lay.name_box = pygame.Rect(inner.left, y, inner.width, box_h)
            typed = self.fit_text(hud.name_entry + "|", normal, inner.width - 2 * gap)
            lay.labels.append(self.label(typed, normal, p.ink, "name",
                                         midleft=(inner.left + gap, lay.name_box.centery)))
            y = lay.name_box.bottom
        hint = self.fit_text(hud.end_hint, small, inner.width)
        lay.labels.append(self.label(hint, small, p.faint, "end", midtop=(inner.centerx, y + gap)))

    # ------------------------------------------------------------------ drawing
    def _background(self, lay: Layout, session: GameSession) -> pygame.Surface:
        """The parts that never move (panels, scene, workspace, the shoulder's base), drawn once per size."""
        key = (lay.size, lay.scene.topleft, lay.scene.size, self.palette.name)
        surface = self._backgrounds.get(key)
        if surface is not None:
            return surface
        if len(self._backgrounds) > 8:
            self._backgrounds.clear()
        p, view = self.palette, lay.view
        surface = pygame.Surface(lay.size).convert() if pygame.display.get_surface() else pygame.Surface(lay.size)
        surface.fill(p.window)
        radius = max(4, round(12 * lay.unit))
        pygame.draw.rect(surface, p.scene, lay.scene, border_radius=radius)
        arm = session.config.arm
        centre = view.to_screen(0.0, 0.0)
        clip = surface.get_clip()
        surface.set_clip(lay.scene)
        # The reachable workspace: the annulus between |l1 - l2| and l1 + l2 from the shoulder.
        outer, inner = view.length(arm.l1 + arm.l2), view.length(abs(arm.l1 - arm.l2))
        pygame.draw.circle(surface, p.workspace, centre, outer)
        pygame.draw.circle(surface, p.scene, centre, inner)
        line = max(MIN_LINE, round(2 * lay.unit))
        pygame.draw.aacircle(surface, p.edge, centre, outer, line)
        pygame.draw.aacircle(surface, p.edge, centre, inner, line)
        # The shoulder is fixed to the body: the torso and head, seen from above, never move.
        draw_torso(surface, view.origin(), view.scale, p)
        surface.set_clip(clip)
        self._backgrounds[key] = surface
        return surface

    def _veil(self, size: tuple[int, int]) -> pygame.Surface:
        veil = self._veils.get(size)
        if veil is None:
            veil = pygame.Surface(size, pygame.SRCALPHA)
            veil.fill((*self.palette.window, 170))
            self._veils = {size: veil}
        return veil

    def invalidate(self) -> None:
        """The next frame is drawn whole: call it after drawing anything else on the window."""
        self._dirty = None

    def draw(self, screen: pygame.Surface, session: GameSession, alpha: float = 1.0, hud: Hud | None = None) -> Layout:
        """One frame; returns its layout.

        On the window itself, only what the last frame drew over is restored from the cached background
        (a 1920 x 1080 copy a frame would cost more than all the rest); elsewhere (a subsurface, an
        off-screen surface) the whole background is drawn.
        """
        hud = hud or Hud()
        lay = self.layout(screen.get_size(), session, hud)
        p, view = self.palette, lay.view
        background = self._background(lay, session)
        frame_key = (id(background), screen.get_size())
        # The corner is always background: if it is not (the window was cleared by a change of mode, or
        # something else drew there), the last frame is not on the window any more.
        if self._dirty is not None and self._frame_key == frame_key and screen is pygame.display.get_surface() \
                and screen.get_at((0, 0)) == background.get_at((0, 0)):
            for rect in self._dirty:
                screen.blit(background, rect, rect)
        else:
            screen.blit(background, (0, 0))
        self._frame_key = frame_key
        dirty: list[pygame.Rect] = []
        arm = session.config.arm
        q1, q2 = session.interpolated_angles(alpha)
        hand = hand_xy(arm.l1, arm.l2, q1, q2)
        clip = screen.get_clip()
        screen.set_clip(lay.scene)
        if len(hud.trail) > 1:
            dirty.append(self._draw_trail(screen, view, hud.trail))
        dirty += self._draw_target(screen, lay, session, hud)
        if session.rules.arm_visible:
            dirty += draw_arm(screen, view.origin(), view.scale, q1, q2, arm.l1, arm.l2,
                              session.muscles.activation, p)
        dirty.append(self._draw_hand(screen, view, hand))
        if hud.paused or hud.ended:
            dirty.append(screen.blit(self._veil(screen.get_size()), (0, 0)))
            if hud.paused and not hud.ended:  # the veil dims the scene; hand and target stay clear
                self._draw_target(screen, lay, session, hud)
                self._draw_hand(screen, view, hand)
        screen.set_clip(clip)
        for rect, i, a in lay.bars:
            dirty.append(pygame.draw.rect(screen, p.bar_back, rect, border_radius=rect.height // 2))
            if a > 0.002:
                fill = rect.copy()
                fill.width = max(rect.height, round(rect.width * a))
                pygame.draw.rect(screen, p.muscles[i], fill, border_radius=rect.height // 2)
        if lay.progress is not None:
            rect, fraction = lay.progress
            dirty.append(pygame.draw.rect(screen, p.bar_back, rect, border_radius=rect.height // 2))
            done = rect.copy()
            done.width = max(rect.height, round(rect.width * fraction))
            pygame.draw.rect(screen, p.link, done, border_radius=rect.height // 2)
        radius = max(4, round(12 * lay.unit))
        for panel in lay.panels:
            dirty.append(pygame.draw.rect(screen, p.panel, panel, border_radius=radius))
            pygame.draw.rect(screen, p.edge, panel, max(MIN_LINE, round(2 * lay.unit)), border_radius=radius)
        for left, right, y in lay.rules:
            dirty.append(pygame.draw.line(screen, p.faint, (left, y), (right, y), max(MIN_LINE, round(2 * lay.unit))))
        if lay.name_box is not None:
            dirty.append(pygame.draw.rect(screen, p.scene, lay.name_box, border_radius=radius // 2))
            pygame.draw.rect(screen, p.ink, lay.name_box, max(1, round(2 * lay.unit)), border_radius=radius // 2)
        for label in lay.labels:
            dirty.append(self.draw_label(screen, label))
        self._dirty = _without_nested([r.inflate(2, 2) for r in dirty if r.width and r.height])
        return lay

    def _draw_trail(self, screen: pygame.Surface, view: Viewport,
                    trail: Sequence[tuple[float, float]]) -> pygame.Rect:
        """The hand's last second: one colour with a contrast of 3:1 or more on the scene, 3 px or wider."""
        points = [view.to_screen(x, y) for x, y in trail]
        width = max(MIN_LINE, view.length(0.008))
        return pygame.draw.lines(screen, self.palette.trail, False, points, width)

    def _draw_target(self, screen: pygame.Surface, lay: Layout, session: GameSession,
                     hud: Hud) -> list[pygame.Rect]:
        """A bullseye (a ring around a dot): a different shape from the hand's solid disc."""
        p, view = self.palette, lay.view
        target = session.rules.target
        centre = view.to_screen(target.x, target.y)
        r = view.length(target.radius)
        newest = min((age for _, _, age in hud.hits), default=None)
        fade = 1.0 if newest is None else min(max(newest / FADE_IN, 0.0), 1.0)
        colour = blend(p.scene, p.target, fade)
        drawn = [pygame.draw.circle(screen, colour, centre, r, max(MIN_LINE, r // 3)),
                 pygame.draw.circle(screen, colour, centre, max(2, r // 4))]
        for x, y, age in hud.hits:
            if age < FLASH_TIME:
                k = age / FLASH_TIME
                where = view.to_screen(x, y)
                drawn.append(pygame.draw.circle(screen, p.flash, where, round(r * (1.0 + 0.8 * k))))
                pygame.draw.aacircle(screen, p.target, where, round(r * (1.0 + 0.8 * k)), max(2, r // 5))
        return drawn

    def _draw_hand(self, screen: pygame.Surface, view: Viewport, hand: tuple[float, float]) -> pygame.Rect:
        # The one thing a player must see, arm hidden or not: a solid disc, larger than the link is wide.
        return pygame.draw.aacircle(screen, self.palette.hand, view.to_screen(*hand), view.length(0.02))
