"""The projector's page in a real browser: a game handed in appears without a reload, every hostile name is
shown as text, and the text reads from the back row at 1024x768; then the teacher's page, in the same browser."""

from __future__ import annotations

import pytest
from browser import browser_page
from class_server import running_class, tapped_game

from armgame.classroom import client

HOSTILE = ['<img src=x onerror="alert(1)">', '"><script>alert(2)</script>',
           "\u05e9\u05dc\u05d5\u05dd <\u05d1>\u05d1\u05d5\u05dc\u05d3</\u05d1>"]


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_the_page_shows_games_as_they_arrive_and_names_as_text_and_the_teacher_acts(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        page.goto(f"http://127.0.0.1:{opened.port}/")
        # (Selectors, not script: the page's content security policy allows no evaluated string.)
        page.wait_for_selector("body[data-version]", state="attached")
        assert code in page.inner_text("#join") and "no games yet" in page.inner_text("#students")
        for i, name in enumerate(HOSTILE):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / f"machine{i}"))
            member = client.join(address, code, name)
            assert client.hand_in(member, tapped_game(i, player=name).to_bytes()).answer is not None
        page.wait_for_selector("#students tr:nth-child(3)", timeout=10_000)
        shown = page.eval_on_selector_all("#students td.name", "cells => cells.map(c => c.textContent)")
        assert sorted(shown) == sorted(HOSTILE)  # the names as typed, as text
        assert page.dialogs == [] and page.query_selector("#students img, #students script, #students b") is None
        news = page.inner_text("#news")
        assert HOSTILE[-1] in news and "first game" in news
        # The back row: every row's text at least 19 px at 1024x768, none of it cut off the page.
        sizes = page.eval_on_selector_all("#students td, #join, .facts", "els => els.map("
                                          "e => parseFloat(getComputedStyle(e).fontSize))")
        assert min(sizes) >= 19
        assert page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")
        page.screenshot(path=str(tmp_path / "class-1024x768.png"))
        _the_teachers_page(page, opened, address, code, tmp_path, monkeypatch)
    assert (tmp_path / "class-1024x768.png").stat().st_size > 10_000


def _the_teachers_page(page, opened, address, code, tmp_path, monkeypatch) -> None:
    """The teacher's page, in the same browser (one chromium for both pages), on the teacher's own machine: open at
    once with no secret typed (none is ever shown), every student listed (names as text) and every joined name by
    the machine it joined from, Hide takes one off the projector, and a name is freed for a student's new
    machine."""
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "ann's machine"))
    client.hand_in(client.join(address, code, "Ann"), tapped_game(7, player="Ann").to_bytes())
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "cy's machine"))
    client.join(address, code, "Cy")  # joined, no game yet
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "the volunteer's machine"))
    client.hand_in(client.join(address, code, "Vi", lab=True), _lab_run(tmp_path, "Vi"))  # a lab run, no game
    page.goto(f"http://127.0.0.1:{opened.port}/teacher")
    page.wait_for_selector(f"#everyone tr:nth-child({len(HOSTILE) + 1})")
    assert not page.is_visible("#ask-secret") and opened.clerk.roster.secret not in page.content()
    page.wait_for_selector("#machines tr:has-text('Cy'):has-text('joined, no game yet')")
    page.wait_for_selector("#machines tr:has-text('Vi'):has-text('lab: 1 run (short)')")
    assert page.inner_text("#waiting") == ("5 students, 1 in the lab only joined; 1 name has handed nothing in yet (no "
                                           "game, no lab run).")
    names = page.eval_on_selector_all("#everyone td:nth-child(2)", "cells => cells.map(c => c.textContent)")
    assert sorted(names) == sorted(["Ann", *HOSTILE]) and page.dialogs == []
    page.click("#everyone tr:has-text('Ann') button")
    page.wait_for_selector("#everyone tr:has-text('Ann'):has-text('hidden on the projector')")
    assert opened.clerk.roster.is_hidden("Ann")
    page.fill("#release-name", "ann")
    page.click("#release")
    page.wait_for_selector("#status:has-text('Ann is free')")
    assert "ann" not in opened.clerk.roster.players and len(opened.clerk.roster.players) == len(HOSTILE) + 2


def _lab_run(tmp_path, name: str) -> bytes:
    """A short lab run (the adapting bot's, relabelled as a person's, as a volunteer's at the keys)."""
    import dataclasses

    from armgame.cli import main
    from armgame.records.replay import Replay

    protocol = tmp_path / "short.toml"
    protocol.write_text('name = "short"\ntargets = 2\ntimeout = 1.5\n[[blocks]]\nname = "field"\ntrials = 2\n'
                        'perturbation = "curl"\nb = 10.0\n')
    assert main(["lab", str(protocol), "--bot", "adaptive", "--headless", "--record", str(tmp_path / "run.json")]) == 0
    replay = Replay.load(tmp_path / "run.json")
    return dataclasses.replace(replay, driven="keyboard", driver=None, player=name).to_bytes()


@pytest.mark.slow
def test_the_class_screenshot_script_draws_every_class_picture(tmp_path, monkeypatch):
    """docs/make_class_screenshots.py cannot rot: it runs here, on a smaller class, into a temporary folder."""
    import importlib.util
    from pathlib import Path

    docs = Path(__file__).resolve().parent.parent / "docs"
    spec = importlib.util.spec_from_file_location("make_class_screenshots", docs / "make_class_screenshots.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    # The script drives chromium through Playwright's own sync API, which one thread runs once at a time: this
    # worker's shared browser (a page test before it) is closed first, and the next page opens it again.
    from browser import close_shared

    close_shared()
    assert script.main_(["--out", str(tmp_path / "img"), "--quick"]) == 0
    drawn = sorted(p.name for p in (tmp_path / "img").iterdir())
    assert drawn == sorted(script.PICTURES) == sorted(p.name for p in (docs / "img").glob("class_*.png"))
    assert all((tmp_path / "img" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" for name in drawn)


def _columns(page) -> list[tuple[str, str | None, float]]:
    """Every student row the projector shows: its name, its count of games (None: not shown), and the name's room
    in ems of its text."""
    return [tuple(row) for row in page.eval_on_selector_all(
        "#students tr", "rows => rows.map(r => { const name = r.querySelector('td.name');"
        " const games = r.querySelector('td.games');"
        " return [name.textContent, games ? games.textContent : null,"
        " name.getBoundingClientRect().width / parseFloat(getComputedStyle(name).fontSize)]; })")]


@pytest.mark.slow  # in chromium
def test_the_projector_keeps_each_students_count_of_games_in_every_column(tmp_path, monkeypatch):
    """docs/teaching.md: the projector "shows each student once, at their best game, with how many they played".
    At 1024x768 thirty students take two columns and sixty two pages of them: every row keeps its count of games,
    its text at 19 px or more and room for a name. The facts count the students apart from the programs."""
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        page.goto(f"http://127.0.0.1:{opened.port}/")
        page.wait_for_selector("body[data-version]", state="attached")
        played: dict[str, int] = {}
        for students in (30, 60):
            while len(played) < students:
                member = client.join(address, code, f"Student {len(played) + 1}")
                played[member.name] = 1 + len(played) % 3  # one, two or three games each
                for game in range(played[member.name]):
                    client.hand_in(member, tapped_game(3 * len(played) + game, player=member.name).to_bytes())
            page.wait_for_selector(f"#people:has-text('{students} students')")
            page.wait_for_timeout(200)
            rows = _columns(page)
            assert page.get_attribute("#students", "data-columns") == "2", students
            assert page.get_attribute("#students", "data-pages") == ("1" if students == 30 else "2")
            assert len(rows) == 30 or students == 60  # sixty: the page with the last arrival
            assert [games for _, games, _ in rows] == [f"{played[name]} game" + "s" * (played[name] > 1)
                                                        for name, _, _ in rows]
            assert min(room for _, _, room in rows) >= 5.5, rows  # "Student 12" whole at any size
            sizes = page.eval_on_selector_all("#students td", "els => els.map(e => parseFloat(getComputedStyle(e)"
                                              ".fontSize))")
            assert min(sizes) >= 19 and page.evaluate("document.documentElement.scrollWidth <= window.innerWidth")
            page.screenshot(path=str(tmp_path / f"class-{students}.png"))
