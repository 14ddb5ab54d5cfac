"""Equal scores share a place, in every view of one table: `armgame scores`, the projector's standings, a
hand-in's answer and the end screens (the window's and the browser's). Each end screen marks one row as the
player's, by who they are, never every row of their place."""

from __future__ import annotations

import argparse
import json
import urllib.request

import pygame
import pytest
from class_server import final_answer, keyboard_game, keyboard_session, running_class

from armgame.classroom import client
from armgame.cli import build_parser, main
from armgame.commands.play import _class_standing, _standing
from armgame.records.scores import ScoreTable
from armgame.records.standings import places
from armgame.ui.render import GameRenderer, Hud

#: Four students, the middle two tied: the seconds of the model bot's keys in each one's game, and its score.
TABLE = (("Ann", 20, 18), ("Bo", 12, 11), ("Cy", 13, 11), ("Dee", 5, 5))
#: Their one ranking: standard competition ranking.
RANKING = [(1, "Ann", 18), (2, "Bo", 11), (2, "Cy", 11), (4, "Dee", 5)]


def test_places_share_equal_scores_and_skip_after_them():
    assert places([30, 20, 20, 10]) == [1, 2, 2, 4]
    assert places([5, 5, 5]) == [1, 1, 1] and places([3, 2, 1]) == [1, 2, 3] and places([]) == []


def _scores_rows(out: str) -> list[tuple[int, str, int]]:
    """The ranked list's (#, name, score) rows of `armgame scores`'s output."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("Ranked")) + 2
    rows = []
    for line in lines[start:]:
        cells = line.split()
        if not cells or not cells[0].isdigit():
            break
        rows.append((int(cells[0]), cells[1], int(cells[2])))
    return rows


def _marked(standing) -> list[str]:
    """The texts the end screen draws in the colour of the player's own row (at 1024 x 768)."""
    pygame.display.init()
    pygame.font.init()
    session = keyboard_session(1)
    renderer = GameRenderer(session.muscles.keys, tuple(m.name for m in session.config.muscles))
    lay = renderer.layout((1024, 768), session, Hud(ended=True, standing=standing))
    return [lab.text for lab in lay.labels if lab.role == "table" and lab.colour == renderer.palette.warn]


def test_every_view_of_a_tied_table_ranks_it_alike_and_marks_only_the_players_row(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        address, code = client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code
        members = {}
        for name, _, _ in TABLE:
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machines" / name))
            members[name] = client.join(address, code, name)
        for name, seconds, score in TABLE:
            if name != "Cy":
                answer = client.hand_in(members[name], keyboard_game(seconds, player=name).to_bytes()).answer
                assert answer["score"] == score
        # Cy's game from the window's end screen: handed in, and the class's top with Cy's own row marked.
        cy = final_answer(_class_standing(keyboard_session(13), argparse.Namespace(bot=None), members["Cy"])(None))
        with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/standings", timeout=10) as r:
            projector = [(row["rank"], row["name"], row["score"]) for row in json.loads(r.read())["students"]]
    assert projector == RANKING
    assert list(cy.top) == RANKING and cy.rank == 2 and cy.top[cy.mine][1] == "Cy"
    assert _marked(cy) == ["2.", "Cy", "11"]
    capsys.readouterr()
    assert main(["scores", "--scores", str(folder)]) == 0
    assert _scores_rows(capsys.readouterr().out) == RANKING
    # The window's end screen at home: the same games in a table of the player's own, Cy's game the last.
    table = ScoreTable(tmp_path / "home")
    for name, seconds, _ in TABLE:
        if name != "Cy":
            table.add(keyboard_game(seconds, player=name))
    args = build_parser().parse_args(["play", "--scores", str(table.folder)])
    cy = _standing(keyboard_session(13), args)("Cy")
    assert list(cy.top) == RANKING and cy.rank == 2 and cy.top[cy.mine][1] == "Cy"
    assert _marked(cy) == ["2.", "Cy", "11"]
    assert "saved to the high-score table as Cy: #2 in the ranked table" in capsys.readouterr().out
    assert main(["scores", "--scores", str(table.folder)]) == 0
    assert _scores_rows(capsys.readouterr().out) == RANKING


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_the_browsers_end_card_marks_only_the_students_own_row(tmp_path):
    from browser import browser_page
    from play_page import join, open_page, to_the_end

    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        open_page(page, f"http://127.0.0.1:{opened.port}")
        join(page, opened.clerk.roster.code, "Cy")
        # The class's answer, as it comes for a student tied with another: the page marks the row it names.
        answer = {"ok": True, "already": False, "name": "Cy", "score": 11, "rank": 2, "of": 4, "best": 11,
                  "list": "students", "note": "first game", "top": [list(row) for row in RANKING], "yours": 2,
                  "message": "handed in: 2nd of 4 in the class (your best so far)"}
        page.route("**/api/handin", lambda route: route.fulfill(status=200, body=json.dumps(answer),
                                                                content_type="application/json"))
        page.keyboard.press("x")
        to_the_end(page)
        page.wait_for_selector("#end-answer:has-text('handed in: 2nd of 4')")
        assert page.eval_on_selector_all("#end-top tr.mine", "rows => rows.map(r => r.textContent)") == ["2.Cy11"]
        assert page.eval_on_selector_all("#end-top tr td.rank", "cells => cells.map(c => c.textContent)") == \
            ["1.", "2.", "2.", "4."]
