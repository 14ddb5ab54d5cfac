"""The front door: a menu window from which each of armgame's windows starts and to which it returns.

The menu knows nothing of commands, score files or settings files: the command line hands it pages
(``Page``) whose items either open another page or start something (``Item.start``, called with the
menu's window closed, since every armgame window opens and closes the display itself). When that
window closes, the menu opens again where it was. An item may hold a ``Field``, a value typed on the
page (a class's address, a name): Enter begins typing, Enter again keeps it if its check takes it (else
the check's one line shows and typing goes on), Esc leaves it as it was. Keys: up/down (or the item's
number) choose, Enter starts, Esc goes back (and quits at the first page), F11 fills the screen; the
mouse hovers and clicks. Like the game's renderer, every frame is laid out before it is drawn
(``MenuWindow.layout``), so the tests check at every window size that no text is cut, overlaps another
or is too small. The palette and ``text_scale`` are the settings' (a bright room's high-contrast, a
large room's 1.5); ``looks``, asked again after every change made on a page, lets the Settings page
show a new text size or palette at once.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import pygame

from ..errors import UserError
from .display import open_window, toggle_fullscreen
from .names import TextRenderer
from .render import PALETTES, Label, min_text

CAPTION = "armgame"
DEFAULT_SIZE = (1024, 720)


@dataclass
class Field:
    """A value typed on a page. ``check`` turns what was typed into the value kept, or raises ValueError
    (or UserError) with the one line the menu shows; ``keep`` is told the value kept, and the page is
    built again (what depends on the value shows it). Nothing is kept anywhere else."""

    value: str = ""
    check: Callable[[str], str] | None = None
    keep: Callable[[str], None] | None = None
    #: The most characters typed.
    limit: int = 80
    #: Shown for an empty value.
    empty: str = "(not set: Enter to type it)"


@dataclass
class Item:
    """One line of a page: ``label`` and a short ``detail``. Enter opens ``page()`` (a page built when
    it is opened, so it shows the table and files as they are now), or calls ``start()`` with the
    menu's window closed (a window of its own), or ``act()`` with it open (a setting changed: the
    page is built again to show it), or types its ``field``. ``start`` and ``act`` return a line for
    the menu to show, or None; ``ready``, asked before ``start``, returns the line that says why it
    cannot start yet (a value still missing), or None."""

    label: str
    detail: str = ""
    page: Callable[[], Page] | None = None
    start: Callable[[], str | None] | None = None
    act: Callable[[], str | None] | None = None
    quit: bool = False
    field: Field | None = None
    ready: Callable[[], str | None] | None = None

    def shown(self) -> str:
        """The item's line: its label, and its field's value."""
        if self.field is None:
            return self.label
        return f"{self.label}: {self.field.value or self.field.empty}"


@dataclass
class Page:
    title: str
    items: list[Item]
    #: Lines shown above the items (the table's top, the settings in force).
    lines: Sequence[str] = ()
    selected: int = 0


@dataclass
class MenuLayout:
    labels: list[Label] = field(default_factory=list)
    #: The items shown (a long page scrolls to keep the chosen one in view): index and clickable rectangle.
    rows: list[tuple[int, pygame.Rect]] = field(default_factory=list)

    def boxes(self) -> list[tuple[str, pygame.Rect]]:
        return [(f"{lab.role}: {lab.text}", lab.rect) for lab in self.labels]


class MenuWindow:
    """The menu in ``screen``; ``frame()`` handles events and draws, ``run()`` loops until quit."""

    def __init__(self, root: Callable[[], Page], palette: str = "okabe-ito", fullscreen: bool = False,
                 size: tuple[int, int] | None = None, text_scale: float = 1.0,
                 looks: Callable[[], tuple[str, float]] | None = None) -> None:
        #: The pages open, first to current, each with what builds it again.
        self.stack: list[tuple[Callable[[], Page], Page]] = [(root, root())]
        #: The palette's name and the text scale in force, asked again after a page's change (None: fixed).
        self.looks = looks
        self.restyle(palette, text_scale)
        self.fullscreen = fullscreen
        self.windowed_size = size
        self.running = True
        self.status = ""
        #: An item to start once the menu's window is closed (set by Enter or a click).
        self.pending: Item | None = None
        #: What is being typed into the chosen item's field (None: not typing).
        self.typing: str | None = None
        #: The text of the key that began typing (its number): SDL sends it again as text just after.
        self._swallow = ""
        self.screen: pygame.Surface | None = None

    def restyle(self, palette: str, text_scale: float) -> None:
        """Draw from now on with ``palette`` and every text ``text_scale`` times its size."""
        self.palette = PALETTES.get(palette, PALETTES["okabe-ito"])
        self.text_scale = text_scale
        # Names typed here are drawn in any script (a student's name, before the class shows it).
        self.renderer = TextRenderer((), (), self.palette, text_scale)

    @property
    def page(self) -> Page:
        return self.stack[-1][1]

    # ------------------------------------------------------------------ input
    def choose(self, index: int) -> None:
        page = self.page
        if not 0 <= index < len(page.items):
            return
        page.selected = index
        item = page.items[index]
        if item.page is not None:
            self.stack.append((item.page, item.page()))
            self.status = ""
        elif item.field is not None:
            self.begin_typing(item.field)
        elif item.start is not None:
            why = item.ready() if item.ready is not None else None
            if why:
                self.status = why
            else:
                self.pending = item
        elif item.act is not None:
            self.status = item.act() or ""
            self.refresh()
        elif item.quit:
            self.running = False

    def refresh(self) -> None:
        """Build the current page again (after a change it shows), keeping the choice."""
        build, old = self.stack[-1]
        page = build()
        page.selected = min(old.selected, max(len(page.items) - 1, 0))
        self.stack[-1] = (build, page)
        if self.looks is not None:
            palette, scale = self.looks()
            if (palette, scale) != (self.palette.name, self.text_scale):
                self.restyle(palette, scale)

    # ----------------------------------------------------------------- typing
    def begin_typing(self, field: Field) -> None:
        self.typing = field.value
        self.status = ""
        pygame.key.start_text_input()
        pygame.key.set_repeat(400, 40)  # a held Backspace deletes on

    def stop_typing(self) -> None:
        self.typing = None
        pygame.key.stop_text_input()
        pygame.key.set_repeat()

    def keep_typed(self) -> None:
        """Enter: the field takes what was typed if its check does; else its line shows, and typing goes on."""
        field = self.page.items[self.page.selected].field
        assert field is not None and self.typing is not None
        try:
            value = field.check(self.typing) if field.check is not None else self.typing
        except (ValueError, UserError) as exc:
            self.status = str(exc)
            return
        field.value = value
        self.stop_typing()
        self.status = ""
        if field.keep is not None:
            field.keep(value)
            self.refresh()

    def type_key(self, event: pygame.event.Event) -> None:
        field = self.page.items[self.page.selected].field
        assert field is not None and self.typing is not None
        if event.type == pygame.TEXTINPUT:
            if self._swallow and event.text == self._swallow:
                self._swallow = ""
                return
            typed = "".join(c for c in event.text if c.isprintable())
            self.typing = (self.typing + typed)[:field.limit]
            return
        self._swallow = ""
        name = pygame.key.name(event.key).lower()
        if name == "escape":
            self.stop_typing()
            self.status = ""
        elif name in ("return", "enter"):
            self.keep_typed()
        elif name == "backspace":
            self.typing = self.typing[:-1]
        elif name == "f11":
            self.screen = toggle_fullscreen(self.windowed_size or self.screen.get_size())
            self.fullscreen = bool(self.screen.get_flags() & pygame.FULLSCREEN)

    def back(self) -> None:
        if len(self.stack) > 1:
            self.stack.pop()
            self.status = ""
        else:
            self.running = False

    def handle(self, event: pygame.event.Event) -> None:
        page = self.page
        if self.typing is not None and event.type in (pygame.TEXTINPUT, pygame.KEYDOWN):
            self.type_key(event)
            return
        if self.typing is not None and event.type in (pygame.MOUSEMOTION, pygame.MOUSEBUTTONDOWN):
            if event.type == pygame.MOUSEMOTION:
                return  # the row being typed stays chosen
            self.stop_typing()  # a click elsewhere leaves the value as it was
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.VIDEORESIZE and not self.fullscreen:
            self.windowed_size = (event.w, event.h)
        elif event.type == pygame.KEYDOWN:
            name = pygame.key.name(event.key).lower()
            if name == "escape":
                self.back()
            elif name == "f11":
                self.screen = toggle_fullscreen(self.windowed_size or self.screen.get_size())
                self.fullscreen = bool(self.screen.get_flags() & pygame.FULLSCREEN)
            elif name in ("up", "down") and page.items:
                page.selected = (page.selected + (1 if name == "down" else -1)) % len(page.items)
            elif name in ("return", "enter", "right"):
                self.choose(page.selected)
            elif name in ("left", "backspace"):
                if len(self.stack) > 1:
                    self.back()
            elif name.isdigit() and name != "0":
                self.choose(int(name) - 1)
                if self.typing is not None:
                    self._swallow = getattr(event, "unicode", "")
        elif event.type == pygame.MOUSEMOTION and self.screen is not None:
            hit = self._row_at(event.pos)
            if hit is not None:
                page.selected = hit
        elif event.type == pygame.MOUSEBUTTONDOWN and event.button == 1 and self.screen is not None:
            hit = self._row_at(event.pos)
            if hit is not None:
                self.choose(hit)
        elif event.type == pygame.MOUSEBUTTONDOWN and event.button == 3:
            self.back()

    def _row_at(self, pos: tuple[int, int]) -> int | None:
        rows = self.layout(self.screen.get_size()).rows
        return next((i for i, r in rows if r.collidepoint(pos)), None)

    def help_items(self) -> tuple[str, ...]:
        if self.typing is not None:
            return ("type", "Backspace deletes", "Enter keeps it", "Esc leaves it as it was")
        back = "Esc back" if len(self.stack) > 1 else "Esc quit"
        count = min(len(self.page.items), 9)
        number = (f"1-{count} start that one",) if count > 1 else ()
        return ("up/down choose", "Enter start", *number, back, "F11 fullscreen", "click to start")

    # ----------------------------------------------------------------- layout
    def layout(self, size: tuple[int, int]) -> MenuLayout:
        """Where every text goes in a window of ``size`` (pure geometry)."""
        w, h = size
        u = min(w, h) / 720.0
        r, p = self.renderer, self.palette
        k = self.text_scale
        small = round(max(min_text(size), round(20 * u)) * k)
        normal = max(small + 2, round(30 * u * k))
        big = max(normal + 4, round(56 * u))  # already large: the room it would take goes to the rows
        pad, gap = max(8, round(28 * u)), max(4, round(10 * u))
        lay = MenuLayout()
        width = w - 2 * pad
        y = pad
        title = r.label(r.fit_text(self.page.title, big, width), big, p.ink, "title", midtop=(w // 2, y))
        lay.labels.append(title)
        y = title.rect.bottom + gap
        help_lines = r.wrap_items(self.help_items(), small, width, gap)
        line_h = r.font(small).get_height()
        bottom = h - pad - len(help_lines) * (line_h + gap // 2)
        status = r.wrap_text(self.status, small, width) if self.status else []
        if status:
            bottom -= len(status) * (line_h + gap // 2) + gap
        column = min(width, max(round(800 * u * max(k, 1.0)), 280))
        left = (w - column) // 2
        items = self.page.items
        content = r.font(normal).get_height() + r.font(small).get_height()
        lines_h = len(self.page.lines) * (line_h + gap // 2) + gap
        # A page too long for its rows with their details (large text, a short window) shows them one
        # line each, the chosen row's detail once above the keys: every item stays on the page.
        compact = lines_h + len(items) * (content + 2 * gap) > bottom - y and any(item.detail for item in items)
        if compact:
            content = r.font(normal).get_height()
            bottom -= line_h + gap
        # Its lines in the middle of the row (seven rows, the main page's, fit a 640 x 480 window).
        row_h = content + (gap if compact else gap + gap // 2)
        # The page's lines give way to its rows: up to three rows (all, if fewer) stay in view.
        rows_room = min(len(items), 3) * (row_h + gap // 2)
        for line in self.page.lines:
            if y + line_h + gap > bottom - rows_room:
                break
            lay.labels.append(r.label(r.fit_text(line, small, width), small, p.faint, "line", midtop=(w // 2, y)))
            y = lay.labels[-1].rect.bottom + gap // 2
        y += gap
        fit = max(1, (bottom - y) // (row_h + gap // 2))
        first = min(max(0, self.page.selected - fit + 1), max(0, len(items) - fit))  # the chosen one in view
        for i in range(first, min(len(items), first + fit)):
            item = items[i]
            rect = pygame.Rect(left, y, column, row_h)
            lay.rows.append((i, rect))
            colour = p.ink
            number = f"{i + 1}  " if i < 9 else "    "
            if self.typing is not None and i == self.page.selected:
                # What is typed keeps its end, where the caret is, in view: its start gives way first.
                prefix = r.fit_text(f"{number}{item.label}: ", normal, (column - 2 * gap) // 2)
                room = column - 2 * gap - r.text_size(prefix, normal)[0]
                text = prefix + r.fit_tail(self.typing + "|", normal, room)
            else:
                text = r.fit_text(number + item.shown(), normal, column - 2 * gap)
            lay.labels.append(r.label(text, normal, colour, "item", topleft=(left + gap, y + (row_h - content) // 2)))
            if item.detail and not compact:
                lay.labels.append(r.label(r.fit_text(item.detail, small, column - 2 * gap), small, p.faint,
                                          "detail", topleft=(left + gap, lay.labels[-1].rect.bottom)))
            y = rect.bottom + gap // 2
        chosen = items[self.page.selected] if 0 <= self.page.selected < len(items) else None
        if compact and chosen is not None and chosen.detail:
            lay.labels.append(r.label(r.fit_text(chosen.detail, small, width), small, p.faint, "detail",
                                      midtop=(w // 2, bottom + gap // 2)))
        y = h - pad
        for line in reversed(help_lines):
            lay.labels.append(r.label(line, small, p.faint, "help", midbottom=(w // 2, y)))
            y = lay.labels[-1].rect.top - gap // 2
        y -= gap // 2
        for line in reversed(status):  # the whole message, on as many lines as it needs
            lay.labels.append(r.label(line, small, p.warn, "status", midbottom=(w // 2, y)))
            y = lay.labels[-1].rect.top - gap // 2
        return lay

    def draw(self) -> MenuLayout:
        screen = self.screen = pygame.display.get_surface() or self.screen
        lay = self.layout(screen.get_size())
        p = self.palette
        screen.fill(p.window)
        radius = max(4, round(10 * min(screen.get_size()) / 720))
        for i, rect in lay.rows:
            selected = i == self.page.selected
            # The row being typed in is a text box: the page's lightest fill.
            fill = p.scene if selected and self.typing is not None else p.bar_back if selected else p.panel
            pygame.draw.rect(screen, fill, rect, border_radius=radius)
            pygame.draw.rect(screen, p.ink if selected else p.edge, rect,
                             max(2, round(3 * min(screen.get_size()) / 720)) if selected else 1,
                             border_radius=radius)
        for lab in lay.labels:
            self.renderer.draw_label(screen, lab)
        return lay

    def frame(self) -> None:
        for event in pygame.event.get():
            self.handle(event)
            if self.pending is not None or not self.running:
                break
        self.draw()
        pygame.display.flip()


def run_menu(root: Callable[[], Page], *, palette: str = "okabe-ito", size: tuple[int, int] | None = None,
             fullscreen: bool = False, fps: int = 30, max_frames: int | None = None, text_scale: float = 1.0,
             looks: Callable[[], tuple[str, float]] | None = None) -> MenuWindow:
    """Show the menu until it is quit; each started item runs with the menu's window closed, then the
    menu opens again on the same page, saying what the item returned."""
    menu = MenuWindow(root, palette, fullscreen, size, text_scale, looks)
    limiter = pygame.time.Clock()
    frames = 0
    while menu.running and (max_frames is None or frames < max_frames):
        menu.screen = open_window(menu.windowed_size or size, menu.fullscreen, CAPTION, DEFAULT_SIZE)
        try:
            while menu.running and menu.pending is None and (max_frames is None or frames < max_frames):
                menu.frame()
                frames += 1
                if fps:
                    limiter.tick(fps)
        finally:
            if not menu.fullscreen:
                menu.windowed_size = menu.screen.get_size()
            pygame.display.quit()
        item, menu.pending = menu.pending, None
        if item is not None and item.start is not None:
            menu.status = item.start() or ""
            menu.refresh()  # what it did may show there (a new score, a new replay)
    return menu
