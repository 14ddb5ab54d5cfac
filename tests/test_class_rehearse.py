"""A rehearsal of the lesson (``armgame class serve --rehearse``): 15 s games, each verified as the class verifies
any game, a 60 s game refused there and a 15 s game refused by a real class, short rounds, REHEARSAL said on every
page, and nothing kept: its folder is gone after Ctrl-C, and neither the data folder's classes nor the teacher's
record of tables (beside the verification cache) is written."""

from __future__ import annotations

import json
import urllib.request
from datetime import timedelta

import pytest
from class_server import keyboard_game, running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.records.replay import Replay
from armgame.records.rulesets import REHEARSAL, RULESETS, class_game_name


@pytest.fixture
def places(tmp_path, monkeypatch):
    """Every place a class could write outside its own folder, in tmp: the data folder (``classes/``), the cache
    (the teacher's records of tables), the system's temporary folder, and each student machine's client folder."""
    import tempfile

    data, cache, temp = tmp_path / "data", tmp_path / "cache", tmp_path / "temp"
    for folder in (cache, temp):
        folder.mkdir(mode=0o700)
    monkeypatch.setenv("XDG_DATA_HOME", str(data))
    monkeypatch.setenv("ARMGAME_CACHE", str(cache))
    monkeypatch.setattr(tempfile, "tempdir", str(temp))

    def machine(name: str) -> None:
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machines" / name))
    return {"data": data, "cache": cache, "temp": temp, "machine": machine}


def get(opened, path: str) -> dict:
    with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}{path}", timeout=10) as r:
        return json.loads(r.read())


def teacher(opened, path: str, body: dict) -> dict:
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", method="POST", data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return json.loads(r.read())


def test_the_rehearsals_game_is_a_ruleset_of_its_own_that_never_ranks():
    assert REHEARSAL.config.time_limit == 15.0 and REHEARSAL.steps == 3750
    assert "rehearsal" not in RULESETS  # a table ranks only 60 s games: a 15 s one is a custom game there
    assert class_game_name(keyboard_game(5, seed=3, duration=15.0).config) == "rehearsal"
    assert class_game_name(keyboard_game(5).config) == "standard"
    assert class_game_name(keyboard_game(5, duration=14.0).config) == "custom"


def test_a_rehearsal_takes_its_15_s_games_refuses_60_s_ones_and_keeps_nothing(places, tmp_path, capsys):
    lines: list[str] = []
    with running_class(None, lines=lines, rehearse=True) as opened:
        folder = opened.clerk.folder
        assert folder.is_dir() and folder.parent.parent == places["temp"]  # the system's temporary folder
        assert lines[0].startswith("armgame class REHEARSAL: code ") and "15 s games, 30 s rounds" in lines[0]
        assert "nothing is kept" in lines[0] and "--folder" not in "\n".join(lines)
        code, address = opened.clerk.roster.code, f"127.0.0.1:{opened.port}"
        places["machine"]("ann")
        ann = client.join(client.ClassAddress.parse(address), code, "Ann")
        assert (ann.duration, ann.rehearsal) == (15.0, True)  # the join answer names the class's game
        taken = client.hand_in(ann, keyboard_game(10, player="Ann", duration=15.0).to_bytes())
        assert taken.answer is not None and taken.message.startswith("handed in: 1st of 1"), taken.message
        refused = client.hand_in(ann, keyboard_game(10, player="Ann").to_bytes())  # a whole 60 s game
        assert refused.refused and "plays the rehearsal game (15 s) of seed 10; this game is standard rules " \
                                   "(60 s)" in refused.message, refused.message
        # The Python game plays the class's clock: 15 s, handed in, verified (a script: a program's game).
        places["machine"]("bo")
        script = tmp_path / "reach.txt"
        script.write_text("0.5 d down\n1.25 d up\n3 j down\n3.5 j up\n", encoding="utf-8")
        record = tmp_path / "bo.json"
        assert main(["play", "--headless", "--script", str(script), "--join", address, "--code", code, "--name",
                     "Bo's script", "--record", str(record)]) == 0
        out, err = capsys.readouterr()
        assert "handed in: " in out and "a rehearsal: 15 s games" in err
        assert Replay.from_bytes(record.read_bytes(), "bo").result.duration == 15.0
        # A round: 30 s whatever the minutes chosen, its winners taken down 25 s after its end.
        assert teacher(opened, "/api/teacher/round", {"minutes": 3})["message"] == \
            "round 1: 30 s (a rehearsal's round), from now"
        rnd = opened.clerk.current_round()
        assert rnd.end - rnd.start == timedelta(seconds=30) and rnd.hold == 25
        s = get(opened, "/api/standings")
        assert s["rehearsal"] is True and s["round"]["hold"] == 25 and s["games"] == 2
        assert teacher(opened, "/api/teacher/close", {"closed": True})["ok"]
    assert not folder.parent.exists()  # the rehearsal's folder, its table and replays, removed at its stop
    assert list(places["temp"].iterdir()) == []
    assert not places["data"].exists() and list(places["cache"].iterdir()) == []


def test_a_class_refuses_a_rehearsal_game_and_keeps_its_teachers_record(places, tmp_path):
    with running_class(tmp_path / "class") as opened:
        places["machine"]("ann")
        ann = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann")
        assert (ann.duration, ann.rehearsal) == (60.0, False)
        refused = client.hand_in(ann, keyboard_game(10, player="Ann", duration=15.0).to_bytes())
        assert refused.refused and "plays the standard game (60 s) of seed 10; this game is rehearsal rules (15 s)" \
            in refused.message, refused.message
        assert get(opened, "/api/standings")["rehearsal"] is False
    # What the rehearsal's test above finds empty, a real class fills: the teacher's record of its table.
    assert [p.name.startswith("table-") for p in places["cache"].iterdir()] == [True]


def test_rehearse_with_a_folder_is_refused_in_one_line(tmp_path, capsys):
    folder = tmp_path / "real"
    assert main(["class", "serve", "--rehearse", "--folder", str(folder), "--host", "127.0.0.1", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "--rehearse keeps nothing" in err and "--folder" in err
    assert not folder.exists()


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_the_browser_plays_the_rehearsals_15_s_game_and_every_page_says_rehearsal(places):
    from browser import browser_page
    from play_page import join, open_page, play_keys, to_the_end

    with running_class(None, rehearse=True) as opened, browser_page(1024, 768) as page:
        base = f"http://127.0.0.1:{opened.port}"
        errors = open_page(page, base)
        join(page, opened.clerk.roster.code, "Zoë")
        sent = []
        page.on("request", lambda r: sent.append(r.post_data) if r.url.endswith("/api/handin") else None)
        play_keys(page, rounds=1)
        to_the_end(page)
        page.wait_for_selector("#end-answer:has-text('handed in: 1st of 1 in the class')")
        replay = Replay.from_bytes(sent[0].encode(), "sent")
        assert replay.config.time_limit == 15.0 and replay.result.duration == 15.0 and replay.result.steps == 3750
        assert class_game_name(replay.config) == "rehearsal"
        shown = int(page.inner_text("#end-score").rsplit(" ", 1)[1])
        assert [(e.name, e.score) for e in opened.clerk.entries] == [("Zoë", shown)]  # verified as the page showed
        assert errors == []
        page.goto(base + "/")
        page.wait_for_selector("#students tr[data-name='Zoë']")
        assert page.inner_text("#rehearsal").startswith("REHEARSAL")
        page.goto(base + "/teacher")
        page.wait_for_selector("#rehearsal", state="visible")
        assert "REHEARSAL" in page.inner_text("header")


def test_the_guide_says_what_a_rehearsal_prints_and_plays(places, tmp_path):
    """docs/teaching.md's rehearsal: the banner's first line and the stop's lines as printed (only the code
    differing), its clocks as the class has them, and the refusal it quotes as the class words it."""
    import re
    from pathlib import Path

    from armgame.classroom.rounds import GRACE_SECONDS, REHEARSAL_ROUND_SECONDS, REHEARSAL_WINNERS_SECONDS
    from armgame.classroom.serve import serve

    guide = (Path(__file__).resolve().parent.parent / "docs" / "teaching.md").read_text(encoding="utf-8")
    section = guide.split("## Rehearse the lesson in five minutes", 1)[1].split("\n## ", 1)[0]
    banner, stopped = (block.split("```", 1)[0] for block in section.split("```text\n")[1:3])
    prose = " ".join(section.split())
    assert f"with {REHEARSAL.config.time_limit:g} s games and {REHEARSAL_ROUND_SECONDS} s rounds" in prose
    assert f"a rehearsal's round lasts {REHEARSAL_ROUND_SECONDS} s" in prose
    assert f"{GRACE_SECONDS} s after its clock runs out the projector shows the winners for " \
           f"{REHEARSAL_WINNERS_SECONDS - GRACE_SECONDS} s" in prose
    with running_class(tmp_path / "class") as opened:
        places["machine"]("bo")
        bo = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Bo")
        refused = client.hand_in(bo, keyboard_game(3, player="Bo", duration=15.0).to_bytes()).message
    quoted = re.search(r'\("(this class plays [^"]+)"\)', prose).group(1)
    assert quoted in refused
    # The banner's first line and the stop's lines (their counts aside): serve() as the command runs it, stopped as
    # soon as it is ready.
    # On a thread of its own, as running_class serves: a worker's chromium (tests/browser.py) keeps an event loop
    # running on the main thread, where asyncio.run cannot start another.
    import threading

    lines: list[str] = []
    status: list[int] = []
    thread = threading.Thread(target=lambda: status.append(serve(
        None, "127.0.0.1", 0, None, say=lines.append, rehearse=True, on_ready=lambda opened: opened.stop())))
    thread.start()
    thread.join(30)
    assert status == [0]
    assert re.fullmatch(re.escape(banner.splitlines()[0]).replace("FROG", "[A-Z]{4}"), lines[0])
    counted = [re.escape(line).replace("4\\ games", r"\d+\ games?").replace("1\\ lab\\ run", r"\d+\ lab\ runs?")
               for line in stopped.splitlines()]
    assert len(lines) >= 2 and all(re.fullmatch(p, line) for p, line in zip(counted, lines[-2:], strict=True)), lines
