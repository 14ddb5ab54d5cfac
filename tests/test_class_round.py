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
from armgame.classroom.rounds import GRACE_SECONDS, WINNERS_SECONDS, Round, Tickets, new_round, round_view
from armgame.records.standings import shared_rank

START = datetime(2026, 11, 27, 10, 0, tzinfo=UTC)


def entry(name: str, score: int, at: timedelta, program: bool = False):
    """An entry handed in ``at`` from the round's start; its id says when (the round takes it by its id)."""
    return SimpleNamespace(name=name, score=score, program=program, id=f"{name}{at.total_seconds():+g}")


def test_a_round_takes_the_games_begun_and_handed_in_during_it_and_its_grace():
    rnd = Round(2, START, 3, after=100)
    assert rnd.end == START + timedelta(minutes=3) and rnd.closes == rnd.end + timedelta(seconds=GRACE_SECONDS)
    begun = START + timedelta(seconds=5)
    assert rnd.refusal(begun, 60, begun + timedelta(seconds=61)) is None
    assert rnd.refusal(begun, 60, rnd.closes - timedelta(milliseconds=1)) is None  # the last instant it takes one
    assert "over" in rnd.refusal(begun, 60, rnd.closes)  # from its close on, none: the projector shows the winners
    assert rnd.over(rnd.closes) and not rnd.over(rnd.closes - timedelta(milliseconds=1))
    assert "no start ticket" in rnd.refusal(None, 60, begun + timedelta(seconds=61))  # a kept replay, an old client
    assert "began before round 2" in rnd.refusal(START - timedelta(seconds=1), 60, begun + timedelta(seconds=61))
    assert "sooner" in rnd.refusal(begun, 60, begun + timedelta(seconds=57))  # a game's length after its ticket
    assert rnd.refusal(begun, 60, begun + timedelta(seconds=58.5)) is None  # within the network's slack
    assert Round.from_dict(rnd.as_dict()) == rnd
    precise = new_round(rnd, 5, 120, START + timedelta(microseconds=123_456))
    assert precise.start == START + timedelta(milliseconds=123) and Round.from_dict(precise.as_dict()) == precise
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
    taken = [e.id for e in best_first if e.id != "Ann-300"]  # the games the clerk took into the round
    during = round_view(rnd, best_first, {"eve"}, START + timedelta(minutes=2), 60, counted=taken)
    assert not during["over"] and during["winners"] == [] and during["players"] == 4
    assert [(r["rank"], r["name"], r["score"], r["games"]) for r in during["students"]] == [
        (1, "Bo", 31, 2), (1, "Cy", 31, 1), (3, "Ann", 22, 1), (4, "Di", 20, 1)]
    after = round_view(rnd, best_first, {"eve"}, START + timedelta(minutes=4), 60, counted=taken)
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
        clock = opened.clerk.clock = FrozenClock()
        client.hand_in(members["Bo"], keyboard_game(40, player="Bo").to_bytes())  # before the round
        assert teacher(opened, "/api/teacher/round", {"minutes": 3})["message"] == "round 1: 3 min, from now"
        rnd = opened.clerk.current_round()
        ticket = client.start_ticket(members["Ann"])  # Ann begins a game during it
        clock.now += timedelta(seconds=61)
        client.hand_in(members["Ann"], keyboard_game(12, player="Ann").to_bytes(), ticket=ticket)
        page.goto(f"http://127.0.0.1:{opened.port}/")
        page.wait_for_selector("body[data-round='on']", state="attached")
        assert page.inner_text("#round-title") == "Round 1: play now!"
        assert page.inner_text("#round-clock").startswith(("3:00", "2:5")) and "left" in page.inner_text("#round-clock")
        names = page.eval_on_selector_all("#students td.name", "cells => cells.map(c => c.textContent)")
        assert names == ["Ann"]  # the round's own standings: Bo's game came before it
        clock.now = rnd.closes  # the round's clock and grace run out: the class says so at once
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


class FrozenClock:
    """The class's clock (``Clerk.clock``) held still at ``now`` (UTC) until the test moves it: a round's minutes in
    a moment, and a hand-in's instant exact."""

    def __init__(self) -> None:
        self.now = datetime.now(UTC)

    def __call__(self) -> datetime:
        return self.now


def post(opened, path: str, member, body: bytes, ticket: str | None = None) -> dict:
    """A joined student's request as their client sends it (their code and token; a game's start ticket)."""
    headers = {"Content-Type": "application/json", "Authorization": f"Bearer {member.token}",
               "X-Armgame-Code": member.code, **({"X-Armgame-Start": ticket} if ticket else {})}
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", method="POST", data=body, headers=headers)
    with urllib.request.urlopen(req, timeout=10) as r:
        return json.loads(r.read())


def start_ticket(opened, member) -> str | None:
    """The ticket the class gives a game beginning now, as the browser game and ``armgame play --join`` ask for it."""
    try:
        return post(opened, "/api/start", member, b"{}").get("ticket")
    except urllib.error.HTTPError:
        return None


def round_now(opened) -> dict:
    with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/standings", timeout=10) as r:
        return json.loads(r.read())["round"]


def students(tmp_path, monkeypatch, opened, *names: str) -> dict:
    address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
    joined = {}
    for name in names:
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
        joined[name] = client.join(address, opened.clerk.roster.code, name)
    return joined


def test_the_winners_are_frozen_at_the_moment_the_projector_says_the_round_is_over(tmp_path, monkeypatch):
    """Issue 54: the projector said "round over" 0.37 s after its clock and grace, and a 55 handed in then still
    counted and became first. One end now: a game taken 0.1 s before it counts, one 0.1 s after it does not, and
    the projector's winners are those from that instant on."""
    with running_class(tmp_path / "class") as opened:
        clock = opened.clerk.clock = FrozenClock()
        joined = students(tmp_path, monkeypatch, opened, "Ann", "Bo", "Cy")
        teacher(opened, "/api/teacher/round", {"minutes": 1})
        rnd = opened.clerk.current_round()
        clock.now = rnd.start + timedelta(seconds=1)  # each begins a game
        tickets = {name: start_ticket(opened, m) for name, m in joined.items()}
        clock.now = rnd.start + timedelta(seconds=62)
        ann = post(opened, "/api/handin", joined["Ann"], keyboard_game(20, player="Ann").to_bytes(), tickets["Ann"])
        clock.now = rnd.closes - timedelta(seconds=0.1)
        bo = post(opened, "/api/handin", joined["Bo"], keyboard_game(30, player="Bo").to_bytes(), tickets["Bo"])
        assert not round_now(opened)["over"]
        clock.now = rnd.closes + timedelta(seconds=0.1)
        cy = post(opened, "/api/handin", joined["Cy"], keyboard_game(60, player="Cy").to_bytes(), tickets["Cy"])
        assert cy["score"] >= 55 and cy["rank"] == 1  # the class's best game: on the board
        assert ann["message"].endswith("; in round 1") and bo["message"].endswith("; in round 1")
        assert cy["message"].endswith("; on the board, not in round 1: round 1 was over when it came")
        shown = round_now(opened)
        assert shown["over"] and shown["closes"] == rnd.closes.isoformat(timespec="milliseconds")
        assert [(w["name"], w["score"]) for w in shown["winners"]] == [("Bo", bo["score"]), ("Ann", ann["score"])]


@pytest.mark.slow  # four games played and a restart
def test_a_latecomer_starts_level_with_a_game_kept_from_before(tmp_path, monkeypatch):
    """Issue 54: a replay played the day before counted in the round. A round counts a game begun during it, as its
    start ticket says (the class's own clock), at least a game's length before it is handed in; a game kept from
    before, begun before the round or handed in sooner than it can be played is on the board, not in the round. The
    round's games are kept: a restart goes on with them."""
    with running_class(tmp_path / "class") as opened:
        clock = opened.clerk.clock = FrozenClock()
        joined = students(tmp_path, monkeypatch, opened, "Ann")
        early = start_ticket(opened, joined["Ann"])  # Ann begins a game before the round
        clock.now += timedelta(seconds=5)
        teacher(opened, "/api/teacher/round", {"minutes": 5})
        rnd = opened.clerk.current_round()
        clock.now = rnd.start + timedelta(seconds=70)
        began = post(opened, "/api/handin", joined["Ann"], keyboard_game(50, player="Ann").to_bytes(), early)
        kept = post(opened, "/api/handin", joined["Ann"], keyboard_game(59, player="Ann").to_bytes())  # yesterday's
        assert began["message"].endswith("not in round 1: it began before round 1 did")
        assert "not in round 1: it has no start ticket from this class" in kept["message"]
        clock.now = rnd.start + timedelta(minutes=2)  # Lee comes late
        joined |= students(tmp_path, monkeypatch, opened, "Lee")
        ticket = start_ticket(opened, joined["Lee"])
        clock.now += timedelta(seconds=10)
        hasty = post(opened, "/api/handin", joined["Lee"], keyboard_game(12, player="Lee").to_bytes(), ticket)
        assert "not in round 1: it came sooner after its start ticket than a 60 s game can be played" in \
            hasty["message"]
        ticket = start_ticket(opened, joined["Lee"])
        clock.now += timedelta(seconds=61)
        lee = post(opened, "/api/handin", joined["Lee"], keyboard_game(20, player="Lee").to_bytes(), ticket)
        again = post(opened, "/api/handin", joined["Lee"], keyboard_game(21, player="Lee").to_bytes(), ticket)
        assert lee["message"].endswith("; in round 1") and "no start ticket" in again["message"]  # used once
        assert lee["score"] < began["score"] < kept["score"]
        assert [(s["rank"], s["name"], s["games"]) for s in round_now(opened)["students"]] == [(1, "Lee", 1)]
    with running_class(tmp_path / "class") as opened:  # restarted during the round
        opened.clerk.clock = FrozenClock()
        opened.clerk.clock.now = rnd.start + timedelta(minutes=4)
        assert [(s["name"], s["score"]) for s in round_now(opened)["students"]] == [("Lee", lee["score"])]


def test_start_tickets_are_used_once_and_bounded_per_player_and_for_the_class():
    tickets = Tickets(per_player=2, most=3)
    first, second, third = (tickets.give("ann", START + timedelta(seconds=i)) for i in range(3))
    assert len(tickets) == 2 and tickets.take(first, "ann") is None  # Ann's oldest made room for her third
    assert tickets.take(second, "bo") is None and tickets.take(second, "ann") == START + timedelta(seconds=1)
    assert tickets.take(second, "ann") is None  # used up
    others = [tickets.give(name, START) for name in ("bo", "cy", "di")]
    assert len(tickets) == 3 and tickets.take(third, "ann") is None  # the class's oldest made room
    assert [tickets.take(t, name) for t, name in zip(others, ("bo", "cy", "di"), strict=True)] == [START] * 3
    assert len(tickets) == 0 and tickets.take(None, "ann") is None


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_the_browser_game_asks_for_its_start_ticket_and_its_game_counts_in_the_round(tmp_path):
    from play_page import join, open_page, play_keys, to_the_end

    with running_class(tmp_path / "class") as opened, browser_page(1024, 768) as page:
        clock = opened.clerk.clock = FrozenClock()
        base = f"http://127.0.0.1:{opened.port}"
        errors = open_page(page, base)
        join(page, opened.clerk.roster.code, "Zoë")
        teacher(opened, "/api/teacher/round", {"minutes": 3})
        sent = []
        page.on("request", lambda r: sent.append(r.headers.get("x-armgame-start")) if r.url.endswith("/api/handin")
                else None)
        play_keys(page)  # the game begins: its ticket asked for
        for _ in range(200):  # the ticket given (asked for as the game began, beside it)
            if len(opened.clerk.tickets):
                break
            time.sleep(0.01)
        clock.now += timedelta(seconds=61)  # the page's own clock runs the game in a moment; the class's, a minute
        to_the_end(page)
        page.wait_for_selector("#end-answer:has-text('; in round 1')")
        assert len(sent) == 1 and sent[0] and errors == []
        assert [s["name"] for s in round_now(opened)["students"]] == ["Zoë"]


def test_the_python_games_window_asks_for_its_start_ticket_and_its_game_counts_in_the_round(tmp_path, monkeypatch,
                                                                                             capsys):
    """``armgame play --join``'s window: the ticket asked for as each game is set up (on a thread), sent with it."""
    import argparse

    from class_server import final_answer, keyboard_session

    from armgame.commands.play import _class_standing

    with running_class(tmp_path / "class") as opened:
        clock = opened.clerk.clock = FrozenClock()
        ann = students(tmp_path, monkeypatch, opened, "Ann")["Ann"]
        teacher(opened, "/api/teacher/round", {"minutes": 3})
        standing = _class_standing(keyboard_session(20), argparse.Namespace(bot=None, record=None), ann)
        for _ in range(500):  # the game begins: its ticket given
            if len(opened.clerk.tickets):
                break
            time.sleep(0.01)
        clock.now += timedelta(seconds=61)
        final_answer(standing(None))
        assert "; in round 1" in capsys.readouterr().out
        assert [s["name"] for s in round_now(opened)["students"]] == ["Ann"]
