"""The live class on loopback: serve, join, hand in, standings per student, and the class kept on disk."""

from __future__ import annotations

import json
import urllib.request

import pytest
from class_server import keyboard_game, running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.records.scores import ScoreTable


@pytest.fixture
def students(tmp_path, monkeypatch):
    """A client folder per student machine: ``machine(name)`` makes its environment current."""
    def machine(name: str) -> None:
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machines" / name))
    return machine


def standings(opened) -> dict:
    with urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/api/standings", timeout=10) as r:
        return json.loads(r.read())


@pytest.mark.slow  # a whole class (2 s): its parts are the tests below and test_class_handin_lines' bot by --join
def test_a_class_from_join_to_standings_one_row_per_student(tmp_path, students, capsys):
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        code = opened.clerk.roster.code
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        results = {}
        for name, presses in (("Ann", [30, 4, 50]), ("Bo", [40]), ("Cy", [10, 20])):
            students(name)
            m = client.join(address, code.lower(), name)  # the code is read whatever its case
            results[name] = [client.hand_in(m, keyboard_game(n, player=name).to_bytes()) for n in presses]
        assert all(r.answer is not None for rs in results.values() for r in rs)
        assert results["Ann"][-1].message.startswith("handed in: ")
        students("Dee")
        assert main(["play", "--headless", "--bot", "model", "--join", f"127.0.0.1:{opened.port}", "--code", code,
                     "--name", "Dee's bot"]) == 0
        assert "among the programs" in capsys.readouterr().out
        # A script's game from the command line, under a name this machine takes as it joins.
        students("Eve")
        script = tmp_path / "reach.txt"
        script.write_text("0.5 d down\n1.25 d up\n", encoding="utf-8")
        assert main(["play", "--headless", "--script", str(script), "--join", f"127.0.0.1:{opened.port}", "--code",
                     code, "--name", "Eve's script"]) == 0
        assert "handed in: " in capsys.readouterr().out
        s = standings(opened)
    people = [(r["name"], r["games"]) for r in s["students"]]
    assert sorted(people) == [("Ann", 3), ("Bo", 1), ("Cy", 2)]  # one row each, with their games played
    programs = {r["name"]: r["driver"] for r in s["programs"]}
    assert programs["Dee's bot"] == "bot (model)" and programs["Eve's script"].startswith("script")
    assert s["joined"] == 5 and s["games"] == 8
    # The folder holds an ordinary table: armgame scores and verify read it afterwards.
    assert len(ScoreTable(folder).all_entries()) == 8
    assert main(["verify", str(folder)]) == 0


def test_the_end_line_names_the_rank_among_students_and_the_best(tmp_path, students):
    with running_class(tmp_path / "class") as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        students("a")
        a = client.join(address, code, "Ann")
        students("b")
        b = client.join(address, code, "Bo")
        first = client.hand_in(a, keyboard_game(20, player="Ann").to_bytes()).answer
        second = client.hand_in(b, keyboard_game(40, player="Bo").to_bytes()).answer
        worse = client.hand_in(a, keyboard_game(5, player="Ann").to_bytes())
    assert first["rank"] == 1 and first["of"] == 1 and first["note"] == "first game"
    assert second["score"] > first["score"] > worse.answer["score"]  # longer play, more hits
    assert second["rank"] == 1 and second["of"] == 2 and second["note"] == "first game"
    assert worse.answer["rank"] == 2 and worse.answer["best"] == first["score"]
    assert worse.message == (f"handed in: score {worse.answer['score']}; your best, {first['score']}, is 2nd of 2 "
                             f"in the class")


def test_a_name_is_the_first_machines_and_a_game_counts_once(tmp_path, students):
    with running_class(tmp_path / "class") as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        students("honest")
        honest = client.join(address, code, "Ann")
        students("other")
        with pytest.raises(client.RefusalError, match="taken"):
            client.join(address, code, "ann ")  # another machine, the same name in another case
        other = client.join(address, code, "Bo")
        game = keyboard_game(12, player="Ann").to_bytes()
        assert client.hand_in(honest, game).answer["already"] is False
        again = client.hand_in(honest, game)  # the same machine again (an answer lost on the way): one game
        assert again.answer["already"] is True and again.message.startswith("already handed in")
        copied = client.hand_in(other, game)  # the same game from another machine, under another name
        assert copied.refused and "already handed in by Ann" in copied.message
        forged = client.Membership(address, code, "Ann", "not-the-token", 10)
        assert client.hand_in(forged, keyboard_game(2).to_bytes()).refused
        students("honest")
        assert client.join(address, code, "Ann").token == honest.token  # the machine that took it rejoins
        assert standings(opened)["games"] == 1


def test_a_game_kept_while_the_class_is_away_is_handed_in_at_the_next_join(tmp_path, students):
    folder = tmp_path / "class"
    students("ann")
    with running_class(folder) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code, port = opened.clerk.roster.code, opened.port
        m = client.join(address, code, "Ann")
    kept = client.hand_in(m, keyboard_game(15, player="Ann").to_bytes())  # the server is gone
    assert kept.kept is not None and kept.kept.is_file() and "kept" in kept.message
    with running_class(folder) as opened:  # the same folder: the same class, code and secret
        assert opened.clerk.roster.code == code and not opened.new
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        lines = client.send_outbox(client.join(address, code, None))  # the name this machine joined under
        assert len(lines) == 1 and "handed in" in lines[0]
        assert not kept.kept.exists()
        assert standings(opened)["games"] == 1
    assert port  # (the port may differ between runs: the join line always shows the current one)


def test_play_join_refuses_what_would_not_be_the_class_game(tmp_path, students, capsys):
    students("x")
    assert main(["play", "--headless", "--bot", "model", "--code", "ABCD"]) == 2
    assert "--code goes with --join" in capsys.readouterr().err
    assert main(["play", "--headless", "--bot", "model", "--join", "127.0.0.1:1", "--name", "x"]) == 2
    assert "--join needs --code" in capsys.readouterr().err
    assert main(["play", "--headless", "--bot", "model", "--join", "127.0.0.1:99999", "--code", "ACDE"]) == 2
    assert "port must be" in capsys.readouterr().err
    assert main(["play", "--headless", "--bot", "model", "--duration", "5", "--join", "127.0.0.1:1",
                 "--code", "ACDE", "--name", "x"]) == 2
    assert "standard 60 s game" in capsys.readouterr().err
    assert main(["play", "--headless", "--bot", "model", "--join", "127.0.0.1:1", "--code", "ACDE",
                 "--name", "x"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the class at 127.0.0.1:1" in err and "school Wi-Fi" in err and len(err.splitlines()) == 1


def test_class_submit_hands_replay_files_in_and_names_each(tmp_path, students, capsys):
    students("ann")
    game = tmp_path / "game.json"
    game.write_bytes(keyboard_game(20, player="Ann").to_bytes())
    (tmp_path / "bad.json").write_text("{")
    with running_class(tmp_path / "class") as opened:
        code = opened.clerk.roster.code
        where = f"127.0.0.1:{opened.port}"
        assert main(["class", "submit", where, "--code", code, "--name", "Ann", str(game)]) == 0
        assert f"{game}: handed in: 1st of 1 in the class" in capsys.readouterr().out
        assert main(["class", "submit", where, "--code", code, str(game), str(tmp_path / "bad.json")]) == 1
        out = capsys.readouterr().out.splitlines()
        assert out[0].startswith(f"{game}: already handed in") and out[1].startswith(f"{tmp_path / 'bad.json'}: not")
        assert main(["class", "submit", where, "--code", "QQQQ", "--name", "Ann", str(game)]) == 2
        assert "wrong class code" in capsys.readouterr().err


def test_a_machine_that_joined_before_plays_on_while_the_class_is_away(tmp_path, students, capsys):
    """The join fails, the game is played with the class's seed all the same, kept, and handed in later."""
    students("ann")
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        code, where = opened.clerk.roster.code, f"127.0.0.1:{opened.port}"
        client.join(client.ClassAddress.parse(where), code, "Ann")
    assert main(["play", "--headless", "--bot", "naive", "--join", where, "--code", code]) == 0
    captured = capsys.readouterr()
    assert "cannot reach the class" in captured.err and "playing on" in captured.err
    assert "kept and will be handed in the next time you join" in captured.out
    with running_class(folder) as opened:
        assert main(["play", "--headless", "--bot", "naive", "--join", f"127.0.0.1:{opened.port}", "--code",
                     code]) == 0
        captured = capsys.readouterr()
        assert "a game kept from before: handed in" in captured.err
        assert "already handed in" in captured.out  # the same bot, the same game: one game
        assert standings(opened)["games"] == 1


def test_the_end_screen_hands_in_on_a_thread_and_shows_what_became_of_the_game(tmp_path, students):
    import argparse
    import time

    from armgame.commands.play import _class_standing
    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession

    students("ann")
    with running_class(tmp_path / "class") as opened:
        member = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann")
        session = GameSession(GameConfig(seed=member.seed))
        session.play([])
        standing = _class_standing(session, argparse.Namespace(bot=None), member)(None)
        assert standing.note == "Handing your game in..." and standing.later is not None
        for _ in range(200):
            final = standing.later()
            if final is not None:
                break
            time.sleep(0.02)
    assert final.note == "Handed in:\n1st of 1 in the class (your best so far)"
    assert final.rank == 1 and final.entries == 1 and final.top == ((1, "Ann", 0),)


def test_the_end_screen_says_in_one_line_that_a_game_is_kept_when_the_class_is_away(tmp_path, students, capsys):
    import argparse
    import time

    from armgame.commands.play import _class_standing
    from armgame.game.rules import GameConfig
    from armgame.game.session import GameSession

    students("ann")
    gone = client.Membership(client.ClassAddress.parse("127.0.0.1:1"), "ACDE", "Ann", "token", 10)
    session = GameSession(GameConfig(seed=10))
    session.play([])
    standing = _class_standing(session, argparse.Namespace(bot=None), gone)(None)
    for _ in range(500):
        final = standing.later()
        if final is not None:
            break
        time.sleep(0.02)
    assert final.note == ("Not handed in: the class cannot be reached.\nYour game is kept: it goes in the next "
                          "time you join")
    out = capsys.readouterr().out  # it joined before: the network reached the class, so no Wi-Fi hint
    assert "the class at 127.0.0.1:1 did not answer" in out and "Wi-Fi" not in out
    assert len(list(client.outbox(gone).glob("*.json"))) == 1


def test_a_folder_printed_for_the_teacher_pastes_whole_into_the_shell(tmp_path):
    """macOS keeps the class under "Application Support": the printed command must survive the space."""
    import shlex

    from armgame.classroom.serve import shell_path

    folder = tmp_path / "Application Support" / "armgame" / "classes" / "it's 2026"
    assert shlex.split(f"armgame class serve --folder {shell_path(folder)}")[-1] == str(folder)
    assert shell_path(tmp_path / "plain") == str(tmp_path / "plain")


def test_the_guide_shows_the_lines_the_class_prints(tmp_path):
    """docs/teaching.md's copy of the banner: line for line what ``armgame class serve`` prints, only the code,
    address, secret and folder differing."""
    import re
    from pathlib import Path

    guide = (Path(__file__).resolve().parent.parent / "docs" / "teaching.md").read_text(encoding="utf-8")
    shown = guide.split("It prints what the class needs", 1)[1].split("```text\n", 1)[1].split("```", 1)[0]
    printed: list[str] = []
    with running_class(tmp_path / "class", lines=printed):
        pass
    variable = {re.escape("FROG"): "[A-Z]{4}", re.escape("192.168.1.20:8765"): r"127\.0\.0\.1:\d+",
                re.escape("3f0a8d30240315451b05"): "[0-9a-f]{20}",
                re.escape("/home/teacher/.local/share/armgame/classes/2026-11-25"): r"\S+"}
    patterns = []
    for line in shown.splitlines():
        pattern = re.escape(line)
        for literal, general in variable.items():
            pattern = pattern.replace(literal, general)
        patterns.append(pattern)
    assert len(printed) == len(patterns), printed
    for pattern, line in zip(patterns, printed, strict=True):
        assert re.fullmatch(pattern, line), (pattern, line)


def test_the_teachers_page_is_a_link_to_open_on_the_laptop_not_a_page_that_opens(tmp_path):
    """Nothing opens a browser: the banner and the guide tell the teacher to open the teacher's link in a browser on
    the laptop, where it asks no secret, and no page says it opens by itself."""
    from pathlib import Path

    printed: list[str] = []
    with running_class(tmp_path / "class", lines=printed):
        pass
    line = next(line for line in printed if "teacher only:" in line)
    assert "/teacher   (open it in a browser on this laptop: it asks no secret here;" in line
    root = Path(__file__).resolve().parent.parent
    guide = " ".join((root / "docs" / "teaching.md").read_text(encoding="utf-8").split())
    assert "open it in a browser on the teacher's laptop (nothing opens one by itself)" in guide
    for text in (guide, (root / "armgame" / "classroom" / "static" / "teacher.html").read_text(encoding="utf-8")):
        assert "opens by itself" not in " ".join(text.split())


def test_a_closed_class_refuses_a_game_before_it_is_played(tmp_path, students, capsys):
    import time

    with running_class(tmp_path / "class") as opened:
        students("ann")
        client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann")
        req = urllib.request.Request(f"http://127.0.0.1:{opened.port}/api/teacher/close", method="POST",
                                     data=b'{"closed": true}', headers={"Content-Type": "application/json"})
        urllib.request.urlopen(req, timeout=10).close()
        started = time.perf_counter()
        assert main(["play", "--headless", "--bot", "model", "--join", f"127.0.0.1:{opened.port}", "--code",
                     opened.clerk.roster.code, "--name", "Ann"]) == 2
        err = capsys.readouterr().err
        assert "is closed: it takes no more games" in err and len(err.strip().splitlines()) == 1
        assert time.perf_counter() - started < 5  # refused at the join, not after a 60 s game


def test_after_class_the_names_the_teacher_hid_stay_hidden_and_the_add_loop_runs_again_quietly(tmp_path, students,
                                                                                               capsys):
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        for name, seconds in (("Ann", 20), ("Bo", 30)):
            students(name)
            client.hand_in(client.join(address, opened.clerk.roster.code, name),
                           keyboard_game(seconds, player=name).to_bytes())
        req = urllib.request.Request(f"http://127.0.0.1:{opened.port}/api/teacher/hide", method="POST",
                                     data=b'{"name": "Bo"}', headers={"Content-Type": "application/json"})
        urllib.request.urlopen(req, timeout=10).close()
    capsys.readouterr()
    assert main(["scores", "--scores", str(folder)]) == 0
    out = capsys.readouterr().out
    assert "Ann" in out and "Bo" not in out and "1 name hidden by the class's teacher" in out
    game = tmp_path / "ann.json"
    keyboard_game(20, player="Ann").save(game)
    table = tmp_path / "offline"
    assert main(["scores", "--scores", str(table), "--new"]) == 0
    assert main(["scores", "--scores", str(table), "--add", str(game)]) == 0
    capsys.readouterr()
    assert main(["scores", "--scores", str(table), "--add", str(game)]) == 0  # the loop run a second time
    captured = capsys.readouterr()
    assert captured.out.startswith("already in: Ann's game") and captured.err == ""
