"""Volunteers' lab runs in a live class: verified, one run per student in the class curve, kept on disk."""

from __future__ import annotations

import csv
import dataclasses
import io
import json
import urllib.request

import pytest
from class_server import running_class

from armgame.classroom import client
from armgame.cli import main
from armgame.records.replay import Replay

#: A two-block protocol with a field and a washout: short to run, and it has an after-effect to mark.
PROTOCOL = ('name = "short"\ntargets = 2\ntimeout = 1.5\n[[blocks]]\nname = "field"\ntrials = 2\n'
            'perturbation = "curl"\nb = 10.0\n[[blocks]]\nname = "washout"\ntrials = 2\n')


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """Three bot runs of the protocol, recorded once: relabelled as people's runs where a test needs that."""
    folder = tmp_path_factory.mktemp("runs")
    (folder / "short.toml").write_text(PROTOCOL)
    for seed in (1, 2, 3):
        assert main(["lab", str(folder / "short.toml"), "--bot", "adaptive", "--headless", "--seed", str(seed),
                     "--record", str(folder / f"run{seed}.json")]) == 0
    return folder


def as_person(path, name: str) -> bytes:
    replay = Replay.load(path)
    return dataclasses.replace(replay, driven="keyboard", driver=None, player=name).to_bytes()


def get(opened, path: str, secret: str | None = None) -> bytes:
    headers = {"Authorization": f"Bearer {secret}"} if secret else {}
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", headers=headers)
    with urllib.request.urlopen(req, timeout=10) as r:
        return r.read()


def test_volunteers_runs_fill_the_class_curve_one_run_each(tmp_path, runs, monkeypatch, capsys):
    folder = tmp_path / "class"
    with running_class(folder, lab=str(runs / "short.toml")) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        members = {}
        for i, name in enumerate(("Ann", "Bo"), 1):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            members[name] = client.join(address, code, name)
            assert "in the class curve" in client.hand_in(members[name], as_person(runs / f"run{i}.json", name)).message
        again = client.hand_in(members["Ann"], as_person(runs / "run3.json", "Ann"))  # a second run: kept apart
        assert "your first run" in again.message
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "bot"))
        assert main(["lab", str(runs / "short.toml"), "--bot", "adaptive", "--headless", "--join",
                     f"127.0.0.1:{opened.port}", "--code", code, "--name", "Bot"]) == 0
        assert "a program's run" in capsys.readouterr().out
        lab = json.loads(get(opened, "/api/lab"))
        data = get(opened, "/api/teacher/lab.csv", opened.clerk.roster.secret)
        assert data.startswith("\ufeff".encode())  # a spreadsheet reads it as UTF-8
        rows = list(csv.DictReader(io.StringIO(data.decode("utf-8-sig"))))
    assert lab["protocol"] == "short" and lab["students"] == 2 and lab["programs"] == 1
    assert lab["metric"] == "max_perpendicular_error_m" and lab["unit"] == "cm"
    assert [t["trial"] for t in lab["trials"]] == [1, 2, 3, 4] and all(t["n"] == 2 for t in lab["trials"])
    assert [t["perturbation"] for t in lab["trials"]][1:3] != ["none", "none"]
    assert {r["player"] for r in rows} == {"Ann", "Bo", "Bot"} and len(rows) == 12
    # lab/ holds each person's first run, the one in the curve; a second run and a program's are kept apart
    assert len(list((folder / "lab").glob("*.json"))) == 2 and len(list((folder / "lab-more").glob("*.json"))) == 2
    # The folder is a class folder analyze reads: the same two students' curve.
    assert main(["analyze", "--class", str(folder / "lab"), "--out", str(tmp_path / "curve"), "--no-figures"]) in (0, 1)
    # Started again on the same folder, the runs are verified again and the curve is the same.
    with running_class(folder) as opened:
        for _ in range(100):
            again = json.loads(get(opened, "/api/lab"))
            if again["students"] == 2:
                break
            import time

            time.sleep(0.05)
    assert again == lab


def test_a_programs_run_handed_in_first_never_takes_the_persons_place(tmp_path, runs, monkeypatch):
    with running_class(tmp_path / "class", lab=str(runs / "short.toml")) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "eve"))
        eve = client.join(address, opened.clerk.roster.code, "Eve")
        program = Replay.load(runs / "run1.json")  # the adapting bot's, as it says
        assert program.driven != "keyboard"
        first = client.hand_in(eve, dataclasses.replace(program, player="Eve").to_bytes())
        assert "a program's run" in first.message and "never in the class curve" in first.message
        mine = client.hand_in(eve, as_person(runs / "run2.json", "Eve"))
        assert mine.message == "lab run handed in: in the class curve"
        lab = json.loads(get(opened, "/api/lab"))
    assert (lab["students"], lab["programs"]) == (1, 1)
    assert len(list((tmp_path / "class" / "lab").glob("*.json"))) == 1


def test_the_curve_is_the_teachers_protocol_not_the_one_most_names_ran(tmp_path, runs, monkeypatch):
    with running_class(tmp_path / "class") as opened:  # a new class's curve: the lesson's
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        for i, name in enumerate(("Ann", "Bo", "Cy"), 1):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            member = client.join(address, opened.clerk.roster.code, name)
            answer = client.hand_in(member, as_person(runs / f"run{i}.json", name))
            assert answer.message == "lab run handed in: kept (the class curve shows the protocol the teacher chose)"
        lab = json.loads(get(opened, "/api/lab"))
        assert (lab["protocol"], lab["students"]) == ("lesson", 0)
        secret = opened.clerk.roster.secret
        req = urllib.request.Request(f"http://127.0.0.1:{opened.port}/api/teacher/lab", data=b'{"protocol": "curl"}',
                                     headers={"Authorization": f"Bearer {secret}", "Content-Type": "application/json"})
        with urllib.request.urlopen(req, timeout=10) as r:
            assert json.loads(r.read())["message"] == "the class curve shows curl"
        assert json.loads(get(opened, "/api/lab"))["protocol"] == "curl"


def post(opened, path: str, body: dict, headers: dict | None = None) -> tuple[int, dict]:
    """A JSON POST from this machine (the teacher's own: its routes need no secret), as a browser's page posts it
    (``headers``: a hand-in's token and code), and the class's answer."""
    req = urllib.request.Request(f"http://127.0.0.1:{opened.port}{path}", data=json.dumps(body).encode(),
                                 headers={"Content-Type": "application/json", **(headers or {})})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as exc:
        return exc.code, json.loads(exc.read())


def test_the_lessons_volunteers_join_a_closed_class_and_their_runs_count_while_games_stay_refused(
        tmp_path, runs, monkeypatch, capsys):
    """docs/teaching.md's order: students play, the teacher closes the class (30-35 min), then the lab runs on
    volunteers (35-47 min). A closed class is closed to new games, and the lab is not one: a join that says it is
    for the lab is taken and its runs reach the class curve; a game, and a new name for a game (the Python game's
    join, the browser's), stay refused, whoever joined. A locked list refuses the lab's new names too."""
    from class_server import tapped_game

    with running_class(tmp_path / "class", lab=str(runs / "short.toml")) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "ann"))
        ann = client.join(address, code, "Ann")
        assert client.hand_in(ann, tapped_game(1, player="Ann").to_bytes()).answer is not None
        assert post(opened, "/api/teacher/close", {"closed": True})[0] == 200
        # The first volunteer, at the keys: joined for the lab, the run in /lab's curve.
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "volunteer"))
        volunteer = client.join(address, code, "Volunteer 1", lab=True)
        assert volunteer.closed
        answer = client.hand_in(volunteer, as_person(runs / "run1.json", "Volunteer 1"))
        assert answer.message == "lab run handed in: in the class curve"
        assert json.loads(get(opened, "/api/lab"))["students"] == 1
        # armgame lab --join says it joins for the lab (here the adapting bot, a program's run: kept apart).
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "volunteer 2"))
        assert main(["lab", str(runs / "short.toml"), "--bot", "adaptive", "--headless", "--join",
                     f"127.0.0.1:{opened.port}", "--code", code, "--name", "Volunteer 2"]) == 0
        said = capsys.readouterr()
        assert "a program's run" in said.out and "it takes this lab run" in said.err
        # A game stays refused, the volunteer's as a student's.
        for member, n in ((volunteer, 2), (ann, 3)):
            refused = client.hand_in(member, tapped_game(n, player=member.name).to_bytes(), keep=False)
            assert refused.refused and "closed to new games" in refused.message
        # A new name for a game: the Python game's join, and the browser's (play.js posts the code and name).
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "late"))
        with pytest.raises(client.RefusalError, match="closed to new games, so it takes no new players"):
            client.join(address, code, "Late")
        assert main(["play", "--headless", "--bot", "model", "--join", f"127.0.0.1:{opened.port}", "--code", code,
                     "--name", "Late"]) == 2
        status, browser = post(opened, "/api/join", {"code": code, "name": "Late B"})
        assert status == 403 and "closed to new games" in browser["error"]
        # The teacher's lock is "nobody new": the lab's volunteers too.
        assert post(opened, "/api/teacher/lock", {"locked": True})[0] == 200
        with pytest.raises(client.RefusalError, match="locked the list"):
            client.join(address, code, "Volunteer 3", lab=True)
        lab = json.loads(get(opened, "/api/lab"))
    assert (lab["students"], lab["programs"]) == (1, 1)
    assert [e.name for e in opened.clerk.entries] == ["Ann"]
    assert {p.name for p in opened.clerk.roster.players.values()} == {"Ann", "Volunteer 1", "Volunteer 2"}


def test_the_projector_counts_students_apart_from_lab_volunteers_and_programs(tmp_path, runs, monkeypatch):
    """A class of two students who played, one about to, a volunteer who only ran the lab, a lab bot and a game bot:
    "3 students · 1 in the lab only · 2 programs", not "6 joined"; the teacher's roster names each one's lab runs."""
    from class_server import tapped_game

    with running_class(tmp_path / "class", lab=str(runs / "short.toml")) as opened:
        address = client.ClassAddress.parse(f"127.0.0.1:{opened.port}")
        code = opened.clerk.roster.code
        members = {}
        for name in ("Ann", "Bo", "Cy", "Vi", "Lab bot", "Game bot"):
            monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / name))
            members[name] = client.join(address, code, name)
        for i, name in enumerate(("Ann", "Bo")):
            assert client.hand_in(members[name], tapped_game(i, player=name).to_bytes()).answer is not None
        client.hand_in(members["Ann"], as_person(runs / "run2.json", "Ann"))  # a student who also ran the lab
        client.hand_in(members["Vi"], as_person(runs / "run1.json", "Vi"))
        client.hand_in(members["Lab bot"], dataclasses.replace(Replay.load(runs / "run3.json"),
                                                               player="Lab bot").to_bytes())
        bot_game = dataclasses.replace(tapped_game(5), driven="bot", driver="model", player="Game bot")
        assert client.hand_in(members["Game bot"], bot_game.to_bytes()).answer["list"] == "programs"
        standings = json.loads(get(opened, "/api/standings"))
        roster = json.loads(get(opened, "/api/teacher/roster", opened.clerk.roster.secret))
    assert standings["people"] == {"students": 3, "lab_only": 1, "programs": 2} and standings["joined"] == 6
    assert roster["people"] == standings["people"] and roster["waiting"] == 1  # Cy: nothing handed in yet
    names = {n["name"]: (n["games"], n["lab"]) for m in roster["machines"] for n in m["names"]}
    assert names == {"Ann": (1, ["short"]), "Bo": (1, []), "Cy": (0, []), "Vi": (0, ["short"]),
                     "Lab bot": (0, ["short"]), "Game bot": (1, [])}


def test_a_lab_run_the_class_refuses_exits_non_zero_with_its_reason(tmp_path, runs, monkeypatch, capsys):
    """As ``armgame play --join`` and ``class submit`` do: a refusal is no success. (What the class refuses of a lab
    run is a forged one, which the command cannot make: the refusal is the class's answer, stood in for here.)"""
    with running_class(tmp_path / "class", lab=str(runs / "short.toml")) as opened:
        monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "bot"))
        refused = client.HandIn("not handed in: the lab run does not reproduce its trials: not taken", refused=True)
        monkeypatch.setattr(client, "hand_in", lambda membership, data, keep=True: refused)
        status = main(["lab", str(runs / "short.toml"), "--bot", "adaptive", "--headless", "--join",
                       f"127.0.0.1:{opened.port}", "--code", opened.clerk.roster.code, "--name", "Bot"])
    err = capsys.readouterr().err
    assert status == 1 and "armgame lab: not handed in: the lab run does not reproduce" in err


def browser_run(seed: int, name: str) -> dict:
    """A browser's lab run as its page writes it (``LabSession(sine="arm")`` of the class's lesson on a person's
    clock: ``labengine.js`` plays it bit for bit, ``tests/test_browser_lab.py``), made here by the adapting bot and
    relabelled as the student's: the replay as JSON data."""
    from armgame.game.bots import Autopilot
    from armgame.lab.bots import make_lab_bot
    from armgame.lab.presets import preset
    from armgame.lab.record import LabTask
    from armgame.lab.session import LabSession, lab_config
    from armgame.records.replay import now_iso

    protocol = preset("lesson")
    session = LabSession(lab_config(protocol, seed, person=True), protocol, sine="arm")
    Autopilot(session, make_lab_bot("adaptive")).play()
    replay = Replay(session.config, tuple(session.timeline), session.result(), "keyboard", None, name, now_iso(),
                    task=LabTask.of(session))
    return json.loads(replay.to_bytes())


def test_a_browsers_lab_run_is_verified_as_any_other_and_a_tampered_trial_is_refused_in_one_line(tmp_path):
    """Handed in through ``/api/handin`` as the page posts it: a run on the arm's sine (``"sine": "arm"``) is
    re-simulated on that sine and enters the class curve; the same kind of run with one trial's record changed (a
    miss made a hit) is refused in one line and stays out of the curve and the folder."""
    honest, tampered = browser_run(21, "Ann"), browser_run(22, "Bo")
    assert honest["task"]["sine"] == tampered["task"]["sine"] == "arm"
    trials = tampered["task"]["trials"]
    i = next((k for k, t in enumerate(trials) if not t[3]), 5)
    trials[i][3] = not trials[i][3]
    with running_class(tmp_path / "class") as opened:  # a new class's curve: the lesson's
        code = opened.clerk.roster.code
        answers = {}
        for name, run in (("Ann", honest), ("Bo", tampered)):
            token = post(opened, "/api/join", {"code": code, "name": name})[1]["token"]
            answers[name] = post(opened, "/api/handin", run, {"Authorization": f"Bearer {token}",
                                                              "X-Armgame-Code": code})
        lab = json.loads(get(opened, "/api/lab"))
    assert answers["Ann"] == (200, {"ok": True, "already": False, "message": "lab run handed in: in the class curve"})
    assert answers["Bo"] == (422, {"ok": False, "error": "the lab run does not reproduce its trials: not taken"})
    assert (lab["protocol"], lab["students"]) == ("lesson", 1) and all(t["n"] == 1 for t in lab["trials"])
    assert [run.player for run in opened.clerk.lab_runs] == ["Ann"]
    assert len(list((tmp_path / "class" / "lab").glob("*.json"))) == 1
