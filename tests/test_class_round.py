"""A round (issue 39): the teacher starts one, the projector counts it down and shows the round's own standings,
and at its end the winners, large; equal scores share a place. The rules in ``classroom.rounds`` first, then a real
class and a real browser."""

from __future__ import annotations

import json
import time
import urllib.request
from datetime import UTC, datetime, timedelta
from types import SimpleNamespace

import pytest
from browser import browser_page
from class_server import keyboard_game, running_class

from armgame.classroom import client
from armgame.classroom.rounds import GRACE_SECONDS, WINNERS_SECONDS, Round, new_round, round_view
from armgame.records.standings import shared_rank

START = datetime(2026, 11, 27, 10, 0, tzinfo=UTC)


def entry(name: str, score: int, at: timedelta, program: bool = False):
    """An entry handed in ``at`` from the round's start (the table's order of entry follows its time)."""
    return SimpleNamespace(name=name, score=score, program=program, entered_at=(START + at).isoformat(),
                           entered=100 + int(at.total_seconds()))


def test_a_round_counts_the_games_handed_in_during_it_and_its_grace():
    rnd = Round(2, START, 3, after=100)
    assert rnd.end == START + timedelta(minutes=3)
    assert not rnd.counts(100, START.isoformat()) and rnd.counts(101, START.isoformat())  # the order, not the second
    assert rnd.counts(102, (rnd.end + timedelta(seconds=GRACE_SECONDS)).isoformat())
    assert not rnd.counts(103, (rnd.end + timedelta(seconds=GRACE_SECONDS + 1)).isoformat())
    assert not rnd.over(rnd.end + timedelta(seconds=GRACE_SECONDS)) and rnd.over(rnd.end + timedelta(seconds=11))
    assert Round.from_dict(rnd.as_dict()) == rnd
    assert new_round(rnd, 5, 120, START) == Round(3, START, 5, 120) and new_round(None, 1, 0, START).number == 1
    for bad in (0, 31, 2.5, True, "3", None):
        with pytest.raises(ValueError, match="whole number of minutes"):
            new_round(rnd, bad, 0, START)
    for bad in ({"number": 1, "start": "2026-11-27T10:00:00", "minutes": 3, "after": 0}, {"number": 0, "start": "x"},
                {**rnd.as_dict(), "after": -1}, [], None):
        with pytest.raises(ValueError):
            Round.from_dict(bad)


def test_the_rounds_standings_best_game_each_equal_scores_sharing_a_place():
    rnd = Round(1, START, 3, after=100)
    best_first = [entry("Ann", 40, timedelta(minutes=-5)),  # before the round: not its game
                  entry("Robo", 39, timedelta(minutes=1), program=True),  # a program: never in a round
                  entry("Bo", 31, timedelta(minutes=1)), entry("Cy", 31, timedelta(minutes=2)),
                  entry("Bo", 30, timedelta(minutes=2)), entry("Ann", 22, timedelta(minutes=2)),
                  entry("Di", 20, timedelta(minutes=1)), entry("Eve", 19, timedelta(minutes=1))]
    during = round_view(rnd, best_first, {"eve"}, START + timedelta(minutes=2), 60)
    assert not during["over"] and during["winners"] == [] and during["players"] == 4
    assert [(r["rank"], r["name"], r["score"], r["games"]) for r in during["students"]] == [
        (1, "Bo", 31, 2), (1, "Cy", 31, 1), (3, "Ann", 22, 1), (4, "Di", 20, 1)]
    after = round_view(rnd, best_first, {"eve"}, START + timedelta(minutes=4), 60)
    assert after["over"] and [w["name"] for w in after["winners"]] == ["Bo", "Cy", "Ann"]
    assert round_view(None, best_first, (), START, 60) is None
    assert [shared_rank(rows, s) for rows, s in (([], 9), ([{"rank": 1, "score": 9}], 9),
                                                  ([{"rank": 1, "score": 9}], 8))] == [1, 1, 2]


def teacher(opened, path: str, body: dict) -> dict:
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", method="POST", data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return json.loads(r.read())


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_the_projector_counts_a_round_down_and_shows_its_winners(tmp_path, monkeypatch):
    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        members = {}
        for name in ("Ann", "Bo"):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            members[name] = client.join(address, opened.clerk.roster.code, name)
        client.hand_in(members["Bo"], keyboard_game(40, player="Bo").to_bytes())  # before the round
        assert teacher(opened, "/api/teacher/round", {"minutes": 3})["message"] == "round 1: 3 min, from now"
        client.hand_in(members["Ann"], keyboard_game(12, player="Ann").to_bytes())  # during it
        page.goto(f"http://127.0.0.1:{opened.port}/")
        page.wait_for_selector("body[data-round='on']", state="attached")
        assert page.inner_text("#round-title") == "Round 1: play now!"
        assert page.inner_text("#round-clock").startswith(("3:00", "2:5")) and "left" in page.inner_text("#round-clock")
        names = page.eval_on_selector_all("#students td.name", "cells => cells.map(c => c.textContent)")
        assert names == ["Ann"]  # the round's own standings: Bo's game came before it
        # The round's clock run out: moved back in the roster's record (as a restart would read it) so that Ann's
        # game came just within its grace, which has run out a second later.
        ann = datetime.fromisoformat(next(e.entered_at for e in opened.clerk.entries if e.name == "Ann"))
        start = ann - timedelta(minutes=1, seconds=GRACE_SECONDS - 1)
        after = opened.clerk.current_round().after
        opened.clerk.roster.changed(round={"number": 1, "start": start.isoformat(timespec="seconds"), "minutes": 1,
                                           "after": after})
        page.wait_for_selector("body[data-round='over']", state="attached", timeout=10_000)
        assert page.inner_text("#winners-title") == "Round 1: the winners"
        assert page.eval_on_selector_all("#winners li .name", "cells => cells.map(c => c.textContent)") == ["Ann"]
        assert page.is_visible("#winners") and not page.is_visible("#round")
        page.screenshot(path=str(tmp_path / "round-end.png"))
        assert teacher(opened, "/api/teacher/round", {"stop": True})["message"] == "round 1 is off the projector"
        page.wait_for_selector("body[data-round='']", state="attached")
        started = time.perf_counter()
        with pytest.raises(urllib.error.HTTPError) as refused:
            teacher(opened, "/api/teacher/round", {"minutes": 99})
        assert refused.value.code == 400 and time.perf_counter() - started < 5


def test_the_guide_says_the_projectors_rules_as_the_page_has_them():
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    guide = " ".join((root / "docs" / "teaching.md").read_text(encoding="utf-8").split())
    script = (root / "armgame" / "classroom" / "static" / "standings.js").read_text(encoding="utf-8")

    def constant(name: str) -> int:
        return int(re.search(rf"const {name} = (\d+);", script).group(1))

    assert WINNERS_SECONDS == 90 and "for a minute and a half" in guide  # the page holds them as the class says
    assert f"turn by themselves every {constant('PAGE_SECONDS')} s" in guide
    assert f"even {constant('MIN_TEXT')} px text" in guide
    assert f"and {GRACE_SECONDS} s more for the last games" in guide


def test_equal_scores_share_a_place_on_the_projector_and_in_the_answer(tmp_path, monkeypatch):
    with running_class(tmp_path / "class") as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        answers = {}
        for name, seconds in (("Ann", 20.0), ("Bo", 20.1), ("Cy", 30.0), ("Di", 5.0)):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            member = client.join(address, opened.clerk.roster.code, name)
            answers[name] = client.hand_in(member, keyboard_game(seconds, player=name).to_bytes()).answer
        assert answers["Ann"]["score"] == answers["Bo"]["score"]  # two games, one score
        with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/standings", timeout=10) as r:
            students = json.loads(r.read())["students"]
    assert [(s["rank"], s["name"]) for s in students] == [(1, "Cy"), (2, "Ann"), (2, "Bo"), (4, "Di")]
    assert answers["Bo"]["rank"] == 1 and answers["Bo"]["message"].startswith("handed in: 1st of 2")  # level with Ann
    assert [row[0] for row in answers["Di"]["top"]] == [1, 2, 2, 4]


def test_the_teacher_renames_a_student_and_their_games_stay_one_row(tmp_path, monkeypatch):
    with running_class(tmp_path / "class") as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "ann"))
        ann = client.join(address, opened.clerk.roster.code, "Ann Bx")
        client.hand_in(ann, keyboard_game(20, player="Ann Bx").to_bytes())
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "bo"))
        client.join(address, opened.clerk.roster.code, "Bo")
        for to, status in (("Bo", 409), ("BO", 409), ("B\u043e", 409), ("Ann\u200b B", 400), ("", 400)):
            with pytest.raises(urllib.error.HTTPError) as refused:
                teacher(opened, "/api/teacher/rename", {"name": "Ann Bx", "to": to})
            assert refused.value.code == status, to
        assert teacher(opened, "/api/teacher/rename", {"name": "ann bx", "to": "Ann B"})["message"] == \
            "Ann Bx is shown as Ann B (the same machine, the same games)"
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "ann"))
        again = client.hand_in(ann, keyboard_game(30, player="Ann Bx").to_bytes()).answer  # the same machine
        assert again["name"] == "Ann B" and again["message"].startswith("handed in: 1st of 1 in the class")
        with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/standings", timeout=10) as r:
            students = json.loads(r.read())["students"]
        assert [(s["name"], s["games"]) for s in students] == [("Ann B", 2)]
    with running_class(tmp_path / "class") as opened:  # a restart keeps the new name
        assert [row.name for row in opened.clerk.boards[False].rows()] == ["Ann B"]
