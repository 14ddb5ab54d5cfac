"""``armgame class show HOST:PORT``: a live class's standings in a window, for a room without a browser.

The same content as the projector's web page (``armgame/classroom/static/standings.*``): the line
students type to join, its code picked out; how many joined, the games handed in, the seed, CLOSED
once the teacher closes the class; the students' best games, one row each; the programs apart
(smaller, beside them or below on a narrow window); and each new arrival said for a few seconds.

The standings are asked for (``GET /api/standings``) about once a second on a thread of their own,
so the window never waits on the network: it draws the last standings it has, with one line saying
why the class cannot be reached while it cannot. What the class answers is hostile until checked
(``parse_standings``): types checked, numbers and lengths bounded, names kept printable and drawn
as text in any script (``names.TextRenderer``). Every frame is laid out first (``ClassWindow.layout``)
so the tests check at each window size that no text is cut, overlaps another or is too small for the
back row: sizes follow the window and the settings' ``text_scale``, and rows that do not fit are
summed up as "and N more", never scrolled.
"""

from __future__ import annotations

import http.client
import json
import threading
import time
import unicodedata
import urllib.error
import urllib.request
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import pygame

from ..classroom.wire import Arrival
from ..words import plural
from .display import open_window, toggle_fullscreen
from .loop import run_loop
from .names import TextRenderer
from .render import PALETTES, RGB, Label, text_heights

if TYPE_CHECKING:
    from ..classroom.client import ClassAddress
    from .settings import Settings

DEFAULT_SIZE = (1280, 720)
FPS = 15
#: How often the class is asked, and how long one answer may take (the window goes on meanwhile).
POLL_SECONDS, TIMEOUT = 1.0, 4.0
#: The most of an answer read: the class sends at most 60 rows a list, a few kilobytes.
MAX_ANSWER = 1 << 20
#: Rows kept of a list, and characters of a name, a program's driver, an arrival's note, the join line.
MAX_ROWS, MAX_NAME, MAX_WORDS, MAX_JOIN = 200, 40, 60, 160
#: Numbers beyond these are not a class's.
MAX_NUMBER = 10**9
#: How long a new arrival is said, in seconds (as the web page does).
NEWS_SECONDS = 6.0
HELP = ("F11 fullscreen", "Esc quit")
CODE_FLAG = "--code "
STUDENTS, PROGRAMS = "Students: best game each", "Programs (bots, scripts)"
#: The most rows any window shows of a list (the programs' width is measured on these).
MAX_SHOWN = 60


# ------------------------------------------------------------------ the class's answer

@dataclass(frozen=True)
class Row:
    rank: int
    name: str
    score: int
    games: int
    driver: str | None = None


@dataclass(frozen=True)
class Standings:
    version: int
    seed: int
    closed: bool
    joined: int
    games: int
    students: tuple[Row, ...]
    programs: tuple[Row, ...]
    arrival: Arrival | None
    join: str
    #: Who joined as the class counts them (students, lab only, programs: ``classroom.views.who_joined``); None
    #: from a class before it, which counted only names.
    people: tuple[int, int, int] | None = None

    def joined_words(self) -> str:
        """'30 students · 2 in the lab only · 3 programs' (the last two where there are any), or 'N joined'."""
        if self.people is None:
            return f"{self.joined} joined"
        students, lab_only, programs = self.people
        return " · ".join([plural(students, "student"), *([f"{lab_only} in the lab only"] if lab_only else []),
                           *([plural(programs, "program")] if programs else [])])


def _text(value: object, what: str, limit: int) -> str:
    """A string from the class: what is not printable dropped (no control or direction characters),
    cut to ``limit`` characters."""
    if not isinstance(value, str):
        raise ValueError(f"{what} is not text")
    kept = "".join(c if c.isprintable() else " " for c in unicodedata.normalize("NFC", value[: 4 * limit])).strip()
    return kept if len(kept) <= limit else kept[: limit - 1] + "…"


def _number(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or abs(value) > MAX_NUMBER:
        raise ValueError(f"{what} is not a whole number")
    return value


def _rows(value: object, what: str) -> tuple[Row, ...]:
    if not isinstance(value, list):
        raise ValueError(f"{what} is not a list")
    rows = []
    for item in value[:MAX_ROWS]:
        if not isinstance(item, dict):
            raise ValueError(f"a row of {what} is not an object")
        driver = item.get("driver")
        rows.append(Row(_number(item.get("rank"), "a rank"), _text(item.get("name"), "a name", MAX_NAME),
                        _number(item.get("score"), "a score"), _number(item.get("games"), "a count of games"),
                        None if driver is None else _text(driver, "a driver", MAX_WORDS)))
    return tuple(rows)


def parse_standings(data: bytes) -> Standings:
    """The class's ``/api/standings`` answer, checked; ValueError names what is not a class's."""
    try:
        value = json.loads(data)
    except (ValueError, RecursionError):
        raise ValueError("not JSON") from None
    if not isinstance(value, dict):
        raise ValueError("not a JSON object")
    closed = value.get("closed")
    if not isinstance(closed, bool):
        raise ValueError("'closed' is not true or false")
    arrival = value.get("arrival")
    if arrival is not None:
        if not isinstance(arrival, dict) or not isinstance(arrival.get("program"), bool):
            raise ValueError("'arrival' is not an arrival")
        note = arrival.get("note")
        arrival = Arrival(_number(arrival.get("seq"), "an arrival's number"),
                          _text(arrival.get("name"), "an arrival's name", MAX_NAME),
                          _number(arrival.get("score"), "an arrival's score"),
                          "" if note is None else _text(note, "an arrival's note", MAX_WORDS), arrival["program"])
    join = value.get("join") or ""  # null: a window that is not the projector's (no --key) shows no code
    people = value.get("people")
    if people is not None:
        if not isinstance(people, dict):
            raise ValueError("'people' is not the count of who joined")
        people = tuple(_number(people.get(k), f"'people' {k}") for k in ("students", "lab_only", "programs"))
    return Standings(_number(value.get("version"), "'version'"), _number(value.get("seed"), "'seed'"), closed,
                     _number(value.get("joined"), "'joined'"), _number(value.get("games"), "'games'"),
                     _rows(value.get("students"), "'students'"), _rows(value.get("programs"), "'programs'"),
                     arrival, _text(join, "'join'", MAX_JOIN), people)


def _reason(exc: BaseException) -> str:
    """What went wrong, in a few words (the error's own, e.g. "Connection refused", "timed out")."""
    if isinstance(exc, urllib.error.HTTPError):
        return f"it answered {exc.code} {_text(str(exc.reason), 'a reason', 40)}"
    reason = getattr(exc, "reason", exc)
    words = getattr(reason, "strerror", None) or str(reason) or type(reason).__name__
    return _text(str(words), "a reason", 60)


class StandingsPoller:
    """Asks ``url`` for the standings every ``interval`` seconds on a daemon thread; ``latest()`` is the
    last standings that arrived and the line saying why the last ask failed (None when it did not)."""

    def __init__(self, url: str, label: str, interval: float = POLL_SECONDS, timeout: float = TIMEOUT,
                 opener: Callable[..., object] = urllib.request.urlopen) -> None:
        self.url, self.label = url, label
        self.interval, self.timeout = interval, timeout
        self._open = opener
        self._lock = threading.Lock()
        self._standings: Standings | None = None
        self._problem: str | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="armgame class standings", daemon=True)

    def start(self) -> StandingsPoller:
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stops asking; never waits for an answer on its way (the thread is a daemon, and ends after it)."""
        self._stop.set()

    def latest(self) -> tuple[Standings | None, str | None]:
        with self._lock:
            return self._standings, self._problem

    def ask(self) -> None:
        """One ask, its answer kept (the thread's loop; the tests call it directly)."""
        try:
            request = urllib.request.Request(self.url, headers={"Accept": "application/json"})
            with self._open(request, timeout=self.timeout) as response:  # type: ignore[attr-defined]
                data = response.read(MAX_ANSWER + 1)
        except (OSError, ValueError, http.client.HTTPException) as exc:
            self._keep(None, f"cannot reach the class at {self.label} ({_reason(exc)}); retrying")
            return
        try:
            if len(data) > MAX_ANSWER:
                raise ValueError(f"larger than {MAX_ANSWER} bytes")
            standings = parse_standings(data)
        except ValueError as exc:
            self._keep(None, f"the answer from {self.label} is not a class's standings ({exc}); retrying")
            return
        self._keep(standings, None)

    def _keep(self, standings: Standings | None, problem: str | None) -> None:
        with self._lock:
            if standings is not None:
                self._standings = standings
            self._problem = problem

    def _run(self) -> None:
        while not self._stop.is_set():
            started = time.monotonic()
            self.ask()
            self._stop.wait(max(0.05, self.interval - (time.monotonic() - started)))


# ------------------------------------------------------------------ layout

@dataclass
class ClassLayout:
    size: tuple[int, int]
    labels: list[Label] = field(default_factory=list)
    #: Filled rectangles drawn under the labels: ("code" | "news" | "fresh", rect).
    panels: list[tuple[str, pygame.Rect]] = field(default_factory=list)
    #: Lines drawn: under a heading, between two columns of a list (from, to).
    rules: list[tuple[tuple[int, int], tuple[int, int]]] = field(default_factory=list)
    #: Where each list goes ("students", "programs"), every label of its rows inside.
    sections: dict[str, pygame.Rect] = field(default_factory=dict)
    #: The rows shown of each list, and how many were summed up as "and N more".
    shown: dict[str, int] = field(default_factory=dict)
    more: dict[str, int] = field(default_factory=dict)

    def boxes(self) -> list[tuple[str, pygame.Rect]]:
        return [(f"{lab.role}: {lab.text}", lab.rect) for lab in self.labels]


class ClassWindow:
    """The standings in ``screen``: ``frame()`` handles events, takes the poller's latest and draws."""

    def __init__(self, label: str, screen: pygame.Surface | None, poller: StandingsPoller | None = None,
                 palette: str = "okabe-ito", text_scale: float = 1.0,
                 clock: Callable[[], float] = time.monotonic) -> None:
        self.label = label
        self.screen = screen
        self.poller = poller
        self.palette = PALETTES.get(palette, PALETTES["okabe-ito"])
        self.renderer = TextRenderer((), (), self.palette, text_scale)
        self.text_scale = text_scale
        self.clock = clock
        self.windowed_size = screen.get_size() if screen is not None else DEFAULT_SIZE
        self.running = True
        self.standings: Standings | None = None
        self.problem: str | None = None
        #: The newest arrival seen (news is only what comes after the window opened), and the one said now.
        self.last_seq: int | None = None
        self.news: Arrival | None = None
        self.news_until = 0.0

    # ------------------------------------------------------------------ data
    def update(self, standings: Standings | None, problem: str | None) -> None:
        """Take what the poller has: a new arrival is said for NEWS_SECONDS, and its row picked out."""
        self.problem = problem
        if self.news is not None and self.clock() >= self.news_until:
            self.news = None
        if standings is None:
            return
        self.standings = standings
        arrival = standings.arrival
        seq = arrival.seq if arrival is not None else 0
        if self.last_seq is None or seq < self.last_seq:  # the first look, or another class: nothing new yet
            self.last_seq = seq
        elif arrival is not None and seq > self.last_seq:
            self.last_seq = seq
            self.news, self.news_until = arrival, self.clock() + NEWS_SECONDS

    # ------------------------------------------------------------------ layout
    def layout(self, size: tuple[int, int]) -> ClassLayout:
        """Where every text goes in a window of ``size`` (pure geometry)."""
        w, h = size
        u = min(w, h) / 720.0
        r, p = self.renderer, self.palette
        big, normal, small = text_heights(size, self.text_scale)
        pad, gap = max(8, round(20 * u)), max(4, round(8 * u))
        lay = ClassLayout(size)
        width = w - 2 * pad
        s = self.standings
        y = self._join_line(lay, s.join if s is not None and s.join else "", round(1.6 * big), small, pad, gap)
        if s is not None:
            y = self._facts(lay, s, normal, y + gap, pad, gap)
        if self.problem:
            problem = self.problem
            if r.text_size(problem, small)[0] > width:  # the reason matters more than the address, shown above
                problem = problem.replace(f" at {self.label}", "")
            lab = r.label(r.fit_text(problem, small, width), small, p.warn, "status", midtop=(w // 2, y + gap))
            lay.labels.append(lab)
            y = lab.rect.bottom
        # The foot: the news while there is some, else the keys; the same height either way (no jumps).
        news_h = big + 2 * gap
        foot = pygame.Rect(pad, h - pad - news_h - 2 * gap, width, news_h + 2 * gap)
        if self.news is not None:
            said = big  # smaller, down to the lists' size, before a long name is cut
            while said > normal and r.text_size(self.news.news, said)[0] > width - 4 * gap:
                said -= 1
            lab = r.label(r.fit_text(self.news.news, said, width - 4 * gap), said, p.ink, "news", center=foot.center)
            lay.panels.append(("news", lab.rect.inflate(4 * gap, 2 * gap).clamp(foot)))
            lay.labels.append(lab)
        else:
            for line in r.wrap_items(HELP, small, width, gap)[:1]:
                lay.labels.append(r.label(line, small, p.faint, "help", midbottom=(w // 2, foot.bottom)))
        body = pygame.Rect(pad, y + 2 * gap, width, foot.top - gap - (y + 2 * gap))
        if s is None:
            wait = f"asking the class at {self.label} for its standings..."
            lay.labels.append(r.label(r.fit_text(wait, normal, width), normal, p.faint, "empty",
                                      midtop=(w // 2, body.top)))
            return lay
        fresh = self.news
        students, programs = self._arrange(body, s, normal, small, gap, landscape=w >= 1.15 * h)
        self._section(lay, "students", students, STUDENTS, s.students, normal, gap,
                      fresh if fresh is not None and not fresh.program else None)
        self._section(lay, "programs", programs, PROGRAMS, s.programs, small, gap,
                      fresh if fresh is not None and fresh.program else None)
        return lay

    def _arrange(self, body: pygame.Rect, s: Standings, normal: int, small: int, gap: int,
                 landscape: bool) -> tuple[pygame.Rect, pygame.Rect]:
        """Where the students' list and the programs' go: side by side on a landscape window, the programs
        below on a narrow one, or on a landscape one where that shows more students (two columns of them)."""
        r = self.renderer
        fixed = r.text_size("999.", small)[0] + r.text_size("9999", small)[0] + 7 * gap
        natural = max([r.text_size(PROGRAMS, small)[0]] + [
            fixed + r.text_size(row.name, small)[0] + r.text_size(row.driver or "", small)[0]
            for row in s.programs[:MAX_SHOWN]])
        pitch = self._line(small) + max(2, gap // 2)
        band = r.text_size(PROGRAMS, small)[1] + gap + max(1, len(s.programs)) * pitch
        below = min(band, body.height // 3)
        # Below, as wide as their rows need on a landscape window (a score far from its name reads badly).
        across = body.width if not landscape else min(body.width, max(natural, body.width // 2))
        stacked = (pygame.Rect(body.left, body.top, body.width, body.height - below - 2 * gap),
                   pygame.Rect(body.left, body.bottom - below, across, below))
        if not landscape:
            return stacked
        # Beside: the programs as wide as their rows need, from 28% to 38% of the width, the rest the
        # students'; narrower, down to 28%, where that makes the students' names whole or gives them a
        # second column.
        wide = round(min(max(natural, 0.28 * body.width), 0.38 * body.width))
        fit = self._fit(body.height, normal, gap)
        want = self._column_need(normal, False, gap, max((r.text_size(row.name, normal)[0]
                                                          for row in s.students[:fit]), default=0))
        two = 2 * self._column_need(normal, False, gap) + 4 * gap
        if len(s.students) > fit and two <= body.width - round(0.28 * body.width) - 2 * gap:
            want = two
        if body.width - 2 * gap - want >= round(0.28 * body.width):  # only where it makes them whole
            wide = min(wide, body.width - 2 * gap - want)
        split = body.width - wide
        side = (pygame.Rect(body.left, body.top, split - 2 * gap, body.height),
                pygame.Rect(body.left + split + 2 * gap, body.top, wide - 2 * gap, body.height))
        n = len(s.students)
        if self._columns(stacked[0], normal, False, gap, n)[2] > self._columns(side[0], normal, False, gap, n)[2]:
            return stacked
        return side

    def _columns(self, area: pygame.Rect, height: int, programs: bool, gap: int, rows: int) -> tuple[int, int, int]:
        """How a list of ``rows`` goes in ``area``: rows per column, columns (two where one would leave
        rows out and each is still wide enough), and the rows shown (the last line says "and N more")."""
        fit = self._fit(area.height, height, gap)
        columns = 2 if rows > fit and area.width >= 2 * self._column_need(height, programs, gap) + 4 * gap else 1
        room = fit * columns
        return fit, columns, rows if rows <= room else max(0, room - 1)

    def _join_line(self, lay: ClassLayout, join: str, largest: int, smallest: int, pad: int, gap: int) -> int:
        """The line students type, as large as fits the width, the code in a box; two lines (before
        ``--code`` and from it) when one does not fit even at the smallest size. Returns its bottom."""
        r, p = self.renderer, self.palette
        w = lay.size[0]
        width = w - 2 * pad
        if not join:  # not heard from the class yet: say which class this is
            title = f"The class at {self.label}"
            lab = r.label(r.fit_text(title, largest, width), largest, p.ink, "join", midtop=(w // 2, pad))
            lay.labels.append(lab)
            return lab.rect.bottom
        at = join.rfind(CODE_FLAG)
        before, code = (join[: at + len(CODE_FLAG)], join[at + len(CODE_FLAG):]) if at >= 0 else (join, "")
        box = 2 * gap  # the code box's margin beside its letters

        def one_line(height: int) -> int:
            return r.text_size(before, height)[0] + (r.text_size(code, height)[0] + 2 * box if code else 0)

        height = largest
        while height > smallest and one_line(height) > width:
            height -= 1
        lines: list[tuple[str, str]]
        if one_line(height) <= width:
            lines = [(before, code)]
        else:
            lines = [(before.removesuffix(CODE_FLAG).rstrip(), ""), (CODE_FLAG if code else "", code)]
            height = largest
            while height > smallest and max(r.text_size(a, height)[0] + (r.text_size(c, height)[0] + 2 * box
                                                                          if c else 0) for a, c in lines) > width:
                height -= 1
        y = pad + gap
        for text, boxed in lines:
            code_w = r.text_size(boxed, height)[0] + 2 * box if boxed else 0
            text = r.fit_text(text, height, width - code_w)
            left = (w - r.text_size(text, height)[0] - code_w) // 2
            lab = r.label(text, height, p.ink, "join", topleft=(left, y))
            lay.labels.append(lab)
            if boxed:
                boxed = r.fit_text(boxed, height, width - lab.rect.width - 2 * box)
                code = r.label(boxed, height, p.panel, "code", topleft=(lab.rect.right + box, y))
                lay.labels.append(code)
                lay.panels.append(("code", code.rect.inflate(2 * box - gap, gap)))
            y = lab.rect.bottom + gap
        return y - gap // 2

    def _facts(self, lay: ClassLayout, s: Standings, height: int, y: int, pad: int, gap: int) -> int:
        """'N students · M games · seed S', and CLOSED beside it (below, if the window is narrow)."""
        r, p = self.renderer, self.palette
        w = lay.size[0]
        width = w - 2 * pad
        facts = f"{s.joined_words()} · {plural(s.games, 'game')} · seed {s.seed}"
        closed = "CLOSED: no more games" if s.closed else ""
        sep = " · "
        fw = r.text_size(facts, height)[0]
        cw = r.text_size(sep + closed, height)[0] if closed else 0
        if fw + cw <= width:
            lab = r.label(facts, height, p.ink, "facts", topleft=((w - fw - cw) // 2, y))
            lay.labels.append(lab)
            if closed:
                lay.labels.append(r.label(sep + closed, height, p.warn, "closed", topleft=(lab.rect.right, y)))
            return lab.rect.bottom
        lab = r.label(r.fit_text(facts, height, width), height, p.ink, "facts", midtop=(w // 2, y))
        lay.labels.append(lab)
        if closed:
            lab = r.label(r.fit_text(closed, height, width), height, p.warn, "closed",
                          midtop=(w // 2, lab.rect.bottom + gap // 2))
            lay.labels.append(lab)
        return lab.rect.bottom

    def _fit(self, height: int, text: int, gap: int) -> int:
        """How many rows of ``text`` px fit under a list's heading in an area ``height`` px tall."""
        r = self.renderer
        line_h = self._line(text)
        pitch = line_h + max(2, gap // 2)
        return max(0, (height - r.text_size(STUDENTS, text)[1] - gap + pitch - line_h) // pitch)

    def _line(self, text: int) -> int:
        """A row's height: the font's line, or more where a descender reaches below it (as SDL measures)."""
        return max(self.renderer.font(text).get_height(), self.renderer.text_size("Agjpqy", text)[1])

    def _column_need(self, height: int, programs: bool, gap: int, name: int | None = None) -> int:
        """The width of a list's column with room for a name ``name`` px wide (default: ten letters) beside
        the rank, the score and the games played or the driver."""
        r = self.renderer
        name = r.text_size("n" * 10, height)[0] if name is None else name
        return (r.text_size("999.", height)[0] + name + r.text_size("9999", height)[0]
                + r.text_size("bot (model)" if programs else "99 games", height)[0] + 5 * gap)

    def _section(self, lay: ClassLayout, key: str, area: pygame.Rect, heading: str, rows: Sequence[Row],
                 height: int, gap: int, fresh: Arrival | None) -> None:
        """A list under its heading: a row each (rank, name, score; games played, or a program's driver),
        in two columns where one would leave rows out and two are wide enough; what still does not fit
        summed up in the last line as "and N more"."""
        r, p = self.renderer, self.palette
        lay.sections[key] = area
        head = r.label(r.fit_text(heading, height, area.width), height, p.ink, "heading", topleft=area.topleft)
        lay.labels.append(head)
        lay.rules.append(((area.left, head.rect.bottom + gap // 2), (area.right, head.rect.bottom + gap // 2)))
        top = head.rect.bottom + gap
        line_h = self._line(height)
        pitch = line_h + max(2, gap // 2)
        fit, columns, shown = self._columns(area, height, key == "programs", gap, len(rows))
        lay.shown[key], lay.more[key] = 0, 0
        if fit == 0:
            return
        if not rows:
            empty = "none yet" if key == "programs" else "no games yet: play, and yours appears here"
            lay.labels.append(r.label(r.fit_text(empty, height, area.width), height, p.faint, "empty",
                                      topleft=(area.left, top)))
            return
        programs = key == "programs"
        rank_w = r.text_size("999.", height)[0]
        score_w = r.text_size("9999", height)[0]
        between = 4 * gap
        col_w = (area.width - (columns - 1) * between) // columns
        if columns == 2:
            x = area.left + col_w + between // 2
            lay.rules.append(((x, top), (x, top + min(fit, max(shown + 1, 1)) * pitch - pitch + line_h)))
        for i, row in enumerate(rows[:shown]):
            column, line = divmod(i, fit)
            left = area.left + column * (col_w + between)
            y = top + line * pitch
            mine = fresh is not None and row.name == fresh.name
            colour: RGB = p.warn if mine else p.ink
            if mine:
                lay.panels.append(("fresh", pygame.Rect(left, y, col_w, line_h).inflate(gap, max(2, gap // 2))
                                   .clip(area)))
            lay.labels.append(r.label(f"{row.rank}.", height, colour, "rank", topright=(left + rank_w, y)))
            right = left + col_w
            lay.labels.append(r.label(str(row.score), height, colour, "score", topright=(right, y)))
            right -= score_w + 2 * gap
            extra = (row.driver or "") if programs else plural(row.games, "game")
            if extra:
                # The name first: the driver or "N games" gets what the name leaves, at least a third of the row
                # (a half for "N games").
                avail = col_w - rank_w - score_w - 5 * gap
                most = max(avail - r.text_size(row.name, height)[0], avail // (3 if programs else 2))
                extra = r.fit_text(extra, height, max(0, most))
                lab = r.label(extra, height, p.faint if not mine else colour, "driver" if programs else "games",
                              topright=(right, y))
                if extra != "...":
                    lay.labels.append(lab)
                    right = lab.rect.left - 2 * gap
            name_left = left + rank_w + gap
            name = r.fit_text(row.name, height, max(0, right - name_left))
            if name != "...":
                lay.labels.append(r.label(name, height, colour, "name", topleft=(name_left, y)))
        lay.shown[key] = shown
        if shown < len(rows):
            lay.more[key] = len(rows) - shown
            column, line = divmod(shown, fit)
            lay.labels.append(r.label(r.fit_text(f"and {len(rows) - shown} more", height, col_w), height, p.faint,
                                      "more", topleft=(area.left + column * (col_w + between), top + line * pitch)))

    # ----------------------------------------------------------------- frames
    def handle(self, event: pygame.event.Event) -> None:
        if event.type == pygame.QUIT:
            self.running = False
        elif event.type == pygame.VIDEORESIZE and self.screen is not None \
                and not self.screen.get_flags() & pygame.FULLSCREEN:
            self.windowed_size = (event.w, event.h)
        elif event.type == pygame.KEYDOWN:
            key = pygame.key.name(event.key).lower()
            if key == "escape":
                self.running = False
            elif key == "f11":
                self.screen = toggle_fullscreen(self.windowed_size)

    def draw(self, screen: pygame.Surface) -> ClassLayout:
        lay = self.layout(screen.get_size())
        p = self.palette
        screen.fill(p.window)
        u = min(lay.size) / 720.0
        radius = max(3, round(8 * u))
        for kind, rect in lay.panels:
            if kind == "code":
                pygame.draw.rect(screen, p.ink, rect, border_radius=radius)
            elif kind == "news":
                pygame.draw.rect(screen, p.panel, rect, border_radius=radius)
                pygame.draw.rect(screen, p.warn, rect, max(3, round(4 * u)), border_radius=radius)
            else:
                pygame.draw.rect(screen, p.bar_back, rect, border_radius=radius)
        for start, end in lay.rules:
            pygame.draw.line(screen, p.faint, start, end, max(2, round(2 * u)))
        for lab in lay.labels:
            self.renderer.draw_label(screen, lab)
        return lay

    def frame(self) -> ClassLayout:
        for event in pygame.event.get():
            self.handle(event)
        self.update(*self.poller.latest()) if self.poller is not None else self.update(None, self.problem)
        screen = self.screen = pygame.display.get_surface() or self.screen
        assert screen is not None
        lay = self.draw(screen)
        pygame.display.flip()
        return lay


def show_class(address: ClassAddress, settings: Settings, fullscreen: bool = False, max_frames: int | None = None,
               screenshot: Path | None = None, key: str | None = None) -> int:
    """The class's standings in a window until Esc or close (``max_frames``: the tests' end). ``screenshot``:
    the first frame with standings on it (or the last frame, if none came) is saved there as a PNG. ``key``: the
    projector link's key, which shows the join code (the teacher's own machine sees it without)."""
    from urllib.parse import quote

    path = "/api/standings" + (f"?key={quote(key, safe='')}" if key else "")
    poller = StandingsPoller(address.url(path), address.label).start()
    try:
        screen = open_window(settings.size, fullscreen, f"armgame: the class at {address.label}", DEFAULT_SIZE)
        window = ClassWindow(address.label, screen, poller, settings.palette, settings.text_scale)
        wanted = [screenshot]

        def shoot() -> None:  # the first frame with standings on it
            if wanted[0] is not None and window.standings is not None:
                pygame.image.save(window.screen, str(wanted[0]))
                wanted[0] = None

        try:
            run_loop(lambda _seconds: window.frame(), lambda: window.running, fps=FPS, max_frames=max_frames,
                     after_frame=shoot)
            if wanted[0] is not None and window.screen is not None:
                pygame.image.save(window.screen, str(wanted[0]))
        finally:
            pygame.display.quit()
    finally:
        poller.stop()
    return 0
