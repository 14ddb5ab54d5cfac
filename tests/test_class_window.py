"""`armgame class show`: the class's standings in a window (SDL's dummy driver), asked of a real class on
loopback on a thread of its own; its layout at the projector sizes with a full class and hostile names; the
answer checked as hostile; names drawn in any script."""

from __future__ import annotations

import os

os.environ["SDL_VIDEODRIVER"] = "dummy"
os.environ["SDL_AUDIODRIVER"] = "dummy"

import io
import json
import socket
import time
from dataclasses import replace

import pygame
import pytest
from class_server import keyboard_game, running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.ui import class_window, names
from armgame.ui.class_window import (
    NEWS_SECONDS,
    Arrival,
    ClassWindow,
    StandingsPoller,
    parse_standings,
    show_class,
)
from armgame.ui.names import TextRenderer, visual_runs
from armgame.ui.render import min_text
from armgame.ui.settings import Settings

SIZES = [(1024, 768), (1280, 800), (1920, 1080), (800, 1280)]
LONG = "Maria-Fernanda Gonzalez de la Cruz Lopez"  # 40 characters, the most a name has
HOSTILE = ["<script>alert(1)</script>", LONG, "שלום עליכם", "محمد علي", "Zoë 李小龙", "' OR 1=1 --", "%s%n{0}",
           "Ǻsa Ångström", "Z\u0301\u0301\u0301\u0301\u0301a\u0327\u0327\u0327lgo"]  # accents, a stack of marks


@pytest.fixture(autouse=True)
def display(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "client"))
    pygame.display.init()
    pygame.font.init()
    yield
    pygame.display.quit()


def answer(students: int = 40, programs: int = 3, closed: bool = True, seq: int = 7, **extra) -> dict:
    names = HOSTILE + [f"Student {i}" for i in range(students)]
    return {"version": 3, "seed": 10, "closed": closed, "joined": students + programs, "games": 2 * students,
            "students": [{"rank": i + 1, "name": names[i], "score": 90 - i, "hits": 90 - i, "games": 1 + i % 12,
                          "driver": None} for i in range(students)],
            "programs": [{"rank": i + 1, "name": f"Dee's bot {i}" if i else "W" * 40, "score": 99 - i, "hits": 99 - i,
                          "games": 1, "driver": "bot (model)"} for i in range(programs)],
            "arrival": {"seq": seq, "name": HOSTILE[0], "score": 90, "note": "new personal best", "program": False},
            "join": "armgame play --join 192.168.100.200:8765 --code HAPF", **extra}


def window(data: dict, problem: str | None = None, text_scale: float = 1.0, news: bool = True) -> ClassWindow:
    now = [100.0]
    w = ClassWindow("192.168.100.200:8765", None, text_scale=text_scale, clock=lambda: now[0])
    w.update(parse_standings(json.dumps(data).encode()), None)
    if news:
        w.update(parse_standings(json.dumps({**data, "arrival": {**data["arrival"], "seq": 8}}).encode()), problem)
    else:
        w.problem = problem
    return w


def check_fits(w: ClassWindow, size: tuple[int, int]) -> class_window.ClassLayout:
    """Every text inside the window and its list's area, none overlapping another, none too small."""
    lay = w.layout(size)
    screen = pygame.Rect((0, 0), size)
    smallest = round(min_text(size) * w.text_scale)
    boxes = lay.boxes()
    for i, (name, rect) in enumerate(boxes):
        assert screen.contains(rect), (size, name, rect)
        assert rect.height >= smallest, (size, name, rect)
        for other, r in boxes[i + 1:]:
            assert not rect.colliderect(r), (size, name, other)
    for kind, rect in lay.panels:
        assert screen.contains(rect), (size, kind)
    for lab in lay.labels if lay.sections else ():
        if lab.role in ("rank", "name", "score", "games", "driver", "more", "empty"):
            assert any(area.contains(lab.rect) for area in lay.sections.values()), (size, lab.role, lab.text)
    return lay


@pytest.mark.parametrize("size", SIZES)
def test_a_full_class_with_hostile_names_fits_every_projector(size):
    w = window(answer(), problem="cannot reach the class at 192.168.100.200:8765 (Connection refused); retrying")
    lay = check_fits(w, size)
    assert w.draw(pygame.Surface(size)).boxes() == lay.boxes()  # every script drawn (fallback fonts, right to left)
    texts = [lab.text for lab in lay.labels]
    # The rows that do not fit are summed up, never lost: shown and "and N more" add up to the class.
    assert lay.shown["students"] + lay.more["students"] == 40 and lay.shown["programs"] == 3
    assert lay.more["students"] == 0 or f"and {lay.more['students']} more" in texts
    assert lay.shown["students"] >= (30 if size[0] >= 1280 else 12)  # two columns where they fit
    assert "HAPF" in texts and any(t.endswith("--code ") for t in texts)  # the code apart, in its box
    assert any(lab.text.startswith("<script>") for lab in lay.labels if lab.role == "name")  # as the characters
    assert any("Connection refused" in t for t in texts) and "CLOSED: no more games" in " ".join(texts)
    news = next(lab.text for lab in lay.labels if lab.role == "news")
    assert news == f"{HOSTILE[0]}: 90, new personal best" or (size[0] < size[1] and news.startswith(HOSTILE[0]))
    # A whole 40-letter name in a class of one column on a wide projector.
    small = check_fits(window(answer(students=10)), size)
    assert size[0] < 1280 or LONG in [lab.text for lab in small.labels]
    # A larger text_scale (the back of a large room) still fits, with the quiet state too.
    check_fits(window(answer(), text_scale=1.5), size)
    check_fits(window(answer(students=0, programs=0), news=False), size)


def test_waiting_and_a_new_arrival_said_for_a_few_seconds():
    now = [0.0]
    w = ClassWindow("127.0.0.1:9", None, clock=lambda: now[0])
    lay = check_fits(w, (1024, 768))
    assert [lab.text for lab in lay.labels if lab.role == "empty"] == \
        ["asking the class at 127.0.0.1:9 for its standings..."]
    first = parse_standings(json.dumps(answer(students=3)).encode())
    w.update(first, None)
    assert w.news is None  # what arrived before the window opened is not news
    w.update(replace(first, arrival=Arrival(8, "Bo", 12, "first game", False)), None)
    assert w.news is not None and "Bo: 12, first game" in [lab.text for lab in w.layout((1024, 768)).labels]
    now[0] += NEWS_SECONDS - 0.1
    w.update(first, None)
    assert w.news is not None
    now[0] += 0.2
    w.update(first, None)
    assert w.news is None and not any(lab.role == "news" for lab in w.layout((1024, 768)).labels)


@pytest.mark.parametrize("data, why", [
    (b"<html>", "not JSON"), (b"[1, 2]", "not a JSON object"), (b"[" * 100_000, "not JSON"),
    (json.dumps({**answer(), "closed": "no"}).encode(), "'closed'"),
    (json.dumps({**answer(), "seed": True}).encode(), "'seed'"),
    (json.dumps({**answer(), "joined": 10**30}).encode(), "'joined'"),
    (json.dumps({**answer(), "people": [30, 2, 3]}).encode(), "'people'"),
    (json.dumps({**answer(), "people": {"students": 30, "lab_only": "2", "programs": 3}}).encode(),
     "'people' lab_only"),
    (json.dumps({**answer(), "students": {"a": 1}}).encode(), "'students' is not a list"),
    (json.dumps({**answer(), "programs": [7]}).encode(), "a row of 'programs'"),
    (json.dumps({**answer(), "students": [{"rank": 1, "name": ["x"], "score": 1, "games": 1}]}).encode(), "a name"),
    (json.dumps({**answer(), "arrival": {"seq": 1}}).encode(), "'arrival'"),
])
def test_an_answer_that_is_not_a_class_s_is_refused_in_words(data, why):
    with pytest.raises(ValueError, match=why):
        parse_standings(data)


def test_text_from_the_class_is_kept_printable_and_short():
    data = answer(students=2)
    data["students"][0]["name"] = "Ann\u202e\x1b[31m" + "x" * 100  # a direction override, a terminal escape
    data["join"] = "armgame play --join h:1 --code ABCD\n\r" + "y" * 500
    s = parse_standings(json.dumps(data).encode())
    name = s.students[0].name
    assert name.isprintable() and len(name) == class_window.MAX_NAME and name.endswith("…") and "\u202e" not in name
    assert s.join.isprintable() and len(s.join) == class_window.MAX_JOIN


class Answer(io.BytesIO):
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_the_poller_says_why_and_keeps_the_last_standings():
    replies = [json.dumps(answer(students=2)).encode(), b"{oops", b" " * (class_window.MAX_ANSWER + 1),
               ConnectionRefusedError(111, "Connection refused")]

    def opener(request, timeout):
        assert timeout == class_window.TIMEOUT and request.full_url == "http://h:1/api/standings"
        reply = replies.pop(0)
        if isinstance(reply, Exception):
            raise reply
        return Answer(reply)

    poller = StandingsPoller("http://h:1/api/standings", "h:1", opener=opener)
    poller.ask()
    good, problem = poller.latest()
    assert good is not None and problem is None and good.students[1].name == HOSTILE[1]
    poller.ask()
    assert poller.latest() == (good, "the answer from h:1 is not a class's standings (not JSON); retrying")
    poller.ask()
    assert "larger than" in poller.latest()[1]
    poller.ask()
    assert poller.latest() == (good, "cannot reach the class at h:1 (Connection refused); retrying")


def test_a_class_that_does_not_answer_never_stalls_the_window():
    with socket.socket() as silent:  # accepts connections (the backlog) and never answers
        silent.bind(("127.0.0.1", 0))
        silent.listen(4)
        port = silent.getsockname()[1]
        poller = StandingsPoller(f"http://127.0.0.1:{port}/api/standings", f"127.0.0.1:{port}", interval=0.05,
                                 timeout=0.25).start()
        screen = pygame.display.set_mode((1024, 768))
        w = ClassWindow(f"127.0.0.1:{port}", screen, poller)
        started = time.monotonic()
        for _ in range(5):
            w.frame()
        assert time.monotonic() - started < 0.3  # five frames while the poller waits for an answer
        deadline = time.monotonic() + 5
        while w.problem is None and time.monotonic() < deadline:
            time.sleep(0.05)
            w.frame()
        poller.stop()
    assert w.problem == f"cannot reach the class at 127.0.0.1:{port} (timed out); retrying"
    assert w.problem in [lab.text for lab in w.frame().labels]


def test_class_show_against_a_real_class(tmp_path, monkeypatch):
    """The whole path: `armgame class show` polls a class on loopback until its standings are drawn."""
    real = ClassWindow.frame

    def frame(self):
        lay = real(self)
        if self.standings is not None and self.standings.students:
            seen.append(lay)
            self.running = False
        return lay

    seen: list[class_window.ClassLayout] = []
    monkeypatch.setattr(ClassWindow, "frame", frame)
    monkeypatch.setattr(class_window, "FPS", 100)
    monkeypatch.setenv("XDG_CONFIG_HOME", str(tmp_path / "config"))
    with running_class(tmp_path / "class") as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        for name, seconds in (("<script>alert(1)</script>", 20), ("Ann", 30)):
            m = client.join(address, code, name)
            assert client.hand_in(m, keyboard_game(seconds, player=name).to_bytes()).answer is not None
        assert main(["class", "show", address.label, "--size", "1024x768"]) == 0
        shot = tmp_path / "shot.png"
        assert show_class(address, Settings(size=(1024, 768)), max_frames=500, screenshot=shot) == 0
    assert len(seen) == 2 and shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    texts = [lab.text for lab in seen[0].labels]
    assert code in texts and "2 students · 2 games · seed 10" in texts
    rows = {lab.rect.top: lab.text for lab in seen[0].labels if lab.role == "rank"}
    ranks = {lab.text: rows[lab.rect.top] for lab in seen[0].labels if lab.role == "name"}
    assert ranks == {"Ann": "1.", "<script>alert(1)</script>": "2."}  # the longer game, the better score


def test_right_to_left_names_read_in_their_order():
    assert visual_runs("Ann") == [("Ann", False)]
    assert visual_runs("שלום 12") == [("12", False), ("שלום ", True)]  # digits still read left to right
    # A digit after right-to-left letters belongs to them (as a browser shows it: "Dee 3 ןדו").
    assert visual_runs("Dee ודן 3") == [("Dee ", False), ("3", False), ("ודן ", True)]
    # Brackets take the line's direction, drawn mirrored right to left: "(Mo) دمحم".
    assert visual_runs("محمد (Mo)") == [(")", True), ("Mo", False), ("محمد (", True)]
    r = TextRenderer()
    assert r.is_plain("Zoë Ольга") and not r.is_plain("שלום")
    path = r._path_for("שלום")
    if path is None:
        pytest.skip("no font with Hebrew on this machine")
    # A font that has the letters, drawn right to left: the same pixels as the letters reversed, drawn left
    # to right; the line as tall as the default font's (rows stay where they were).
    (run, font), = r._pieces("שלום", 30)
    assert run == "שלום" and font is r._run_font(path, 30, True, "Hebr")
    ltr = r._run_font(path, 30, False, None)
    if names._has_harfbuzz():
        assert pygame.image.tobytes(font.render(run, True, (0, 0, 0), (255, 255, 255)), "RGB") == \
            pygame.image.tobytes(ltr.render(run[::-1], True, (0, 0, 0), (255, 255, 255)), "RGB")
    assert r.text_size("שלום", 30) == (ltr.size(run)[0], r.font(30).get_height())


def test_the_facts_count_students_apart_from_the_labs_volunteers_and_the_programs():
    w = window(answer(students=30, programs=3, closed=False, people={"students": 30, "lab_only": 2, "programs": 3}))
    facts = [lab.text for lab in w.layout((1024, 768)).labels if lab.role == "facts"]
    assert facts == ["30 students · 2 in the lab only · 3 programs · 60 games · seed 10"]
    w = window(answer(students=1, programs=0, closed=False, people={"students": 1, "lab_only": 0, "programs": 0}))
    facts = [lab.text for lab in w.layout((1024, 768)).labels if lab.role == "facts"]
    assert facts == ["1 student · 2 games · seed 10"]
