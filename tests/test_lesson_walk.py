"""docs/teaching.md's lesson walked in its own order, with its own commands, as a new teacher follows it: the
class served, three students and a bot joining and handing in, a round, the class closed, a volunteer's lab
run after it, the projector's lists and curve, Ctrl-C, and the commands that read the class afterwards.

The students' games are keyboard games handed in with ``armgame class submit`` (the documented way to hand
in a recorded game: a window's keys cannot be typed here); the volunteer's run is the adapting bot's, relabelled
as a person's, handed in the same way. Everything else is the command the plan prints."""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import subprocess
import sys
import urllib.request
from pathlib import Path

import pytest
from class_server import free_port, keyboard_game, serve_process

from armgame.classroom import client
from armgame.lab import record as _lab_record  # noqa: F401 (registers the lab's task section, to read a run)
from armgame.records.replay import Replay

ROOT = Path(__file__).resolve().parent.parent
TEACHING = ROOT / "docs" / "teaching.md"
STUDENTS = ("Kofi A", "Ann B", "Zoë F")

pytestmark = pytest.mark.skipif(not hasattr(signal, "SIGINT"), reason="Ctrl-C is sent as SIGINT")


def test_the_walk_types_the_commands_the_plan_prints_in_the_plan_s_order():
    doc = TEACHING.read_text(encoding="utf-8")
    for command in ('armgame class serve', 'armgame play --join 192.168.1.20:8765 --code FROG --name "Ann B"',
                    'armgame play --headless --bot model --join', 'armgame class submit ADDRESS --code CODE FILE',
                    'armgame lab lesson --join 192.168.1.20:8765 --code FROG --name "Volunteer 1"',
                    'armgame scores --scores', 'armgame verify', 'armgame analyze --class'):
        assert command in doc, command
    # The plan closes the class before its lab: the walk below does the same.
    assert doc.index("Close the class to new games") < doc.index("**35-47 min: the lab")


def armgame(*args: str, machine: Path, cwd: Path) -> subprocess.CompletedProcess:
    """One command as a student's or the teacher's terminal runs it; ``machine``: whose memberships it keeps."""
    env = {**os.environ, client.CLIENT_ENV: str(machine)}
    return subprocess.run([sys.executable, "-m", "armgame", *args], capture_output=True, text=True, env=env,
                          cwd=cwd, timeout=120)


def teacher(port: int, path: str, body: dict | None = None) -> dict:
    """A teacher's-page request from the teacher's own machine (loopback: no secret asked)."""
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(f"http://127.0.0.1:{port}{path}", data=data, method="GET" if data is None else "POST",
                                 headers={"Content-Type": "application/json"})
    with urllib.request.urlopen(req, timeout=10) as r:
        return json.loads(r.read())


@pytest.mark.slow  # a server and a dozen armgame processes: about 15 s
def test_the_lesson_plan_runs_as_written_students_a_bot_a_round_the_class_closed_and_the_lab_after_it(tmp_path):
    folder, port = tmp_path / "class", free_port()
    address = f"127.0.0.1:{port}"
    machines = {name: tmp_path / f"machine-{i}" for i, name in enumerate((*STUDENTS, "Volunteer 1"))}
    games = tmp_path / "games"
    games.mkdir()
    proc, code = serve_process(folder, port, "--lab", "lesson")
    try:
        # 15-30 min: the students play; every game is handed in by itself.
        for i, name in enumerate(STUDENTS):
            path = games / f"{i}.json"
            path.write_bytes(keyboard_game(10 + 5 * i, player=name).to_bytes())
            done = armgame("class", "submit", address, "--code", code.lower(), "--name", name, str(path),
                           machine=machines[name], cwd=tmp_path)
            assert done.returncode == 0, done.stdout + done.stderr
        # A bot joins too, from a student's own machine, under a name of its own ...
        done = armgame("play", "--headless", "--bot", "model", "--join", address, "--code", code, "--name",
                       "Kofi's robot", machine=machines["Kofi A"], cwd=tmp_path)
        assert done.returncode == 0, done.stdout + done.stderr
        # ... and the student plays on under theirs, from the same machine.
        path = games / "kofi-2.json"
        path.write_bytes(keyboard_game(40, player="Kofi A").to_bytes())
        done = armgame("class", "submit", address, "--code", code, "--name", "Kofi A", str(path),
                       machine=machines["Kofi A"], cwd=tmp_path)
        assert done.returncode == 0, done.stdout + done.stderr
        # 25-28 min: a round; a replay file handed in during it is on the board, not in the round (nothing says it
        # was played during the round: a game played in it has the class's start ticket, tests/test_class_round.py).
        assert teacher(port, "/api/teacher/round", {"minutes": 3})["ok"]
        path = games / "ann-2.json"
        path.write_bytes(keyboard_game(45, player="Ann B").to_bytes())
        done = armgame("class", "submit", address, "--code", code, str(path), machine=machines["Ann B"], cwd=tmp_path)
        assert done.returncode == 0 and "not in round 1: it has no start ticket" in done.stdout, \
            done.stdout + done.stderr
        standings = teacher(port, "/api/standings")
        assert standings["round"]["students"] == []
        assert {row["name"] for row in standings["students"]} == set(STUDENTS)
        assert next(r for r in standings["students"] if r["name"] == "Kofi A")["games"] == 2
        assert [row["name"] for row in standings["programs"]] == ["Kofi's robot"]
        # 30-35 min: the class closed to new games; a game handed in now is refused, and the command says so.
        assert teacher(port, "/api/teacher/close", {"closed": True})["ok"]
        path = games / "zoe-late.json"
        path.write_bytes(keyboard_game(50, player="Zoë F").to_bytes())
        done = armgame("class", "submit", address, "--code", code, str(path), machine=machines["Zoë F"], cwd=tmp_path)
        assert done.returncode != 0 and "closed" in done.stdout + done.stderr, done.stdout + done.stderr
        # 35-47 min: the lab, on a volunteer who joins the closed class (the lab is not a new game).
        run = tmp_path / "volunteer.json"
        done = armgame("lab", "lesson", "--bot", "adaptive", "--headless", "--seed", "3", "--record", str(run),
                       machine=machines["Volunteer 1"], cwd=tmp_path)
        assert done.returncode == 0, done.stdout + done.stderr
        replay = Replay.load(run)
        run.write_bytes(dataclasses.replace(replay, driven="keyboard", driver=None, player="Volunteer 1").to_bytes())
        done = armgame("class", "submit", address, "--code", code, "--name", "Volunteer 1", str(run),
                       machine=machines["Volunteer 1"], cwd=tmp_path)
        assert done.returncode == 0, done.stdout + done.stderr
        # 47-50 min: the class curve on the projector: the volunteer's run, n = 1.
        curve = teacher(port, "/api/lab")
        assert curve["students"] == 1 and curve["protocol"] == "lesson", curve
        people = teacher(port, "/api/standings")["people"]
        assert people == {"students": 3, "lab_only": 1, "programs": 1}, people
        roster = json.dumps(teacher(port, "/api/teacher/roster"))
        assert "Volunteer 1" in roster and "lesson" in roster, roster
    finally:
        proc.send_signal(signal.SIGINT)  # Ctrl-C
        out, _ = proc.communicate(timeout=30)
    assert proc.returncode == 0, out
    # After the class: the commands Ctrl-C printed read the class's folder, each checking every game again.
    assert f"armgame scores --scores {folder}" in out and f"armgame analyze --class {folder / 'lab'}" in out, out
    done = armgame("scores", "--scores", str(folder), machine=tmp_path / "teacher", cwd=tmp_path)
    assert done.returncode == 0 and all(name in done.stdout for name in STUDENTS), done.stdout + done.stderr
    done = armgame("verify", str(folder), machine=tmp_path / "teacher", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    done = armgame("analyze", "--class", str(folder / "lab"), "--out", str(tmp_path / "curve"), "--no-figures",
                   machine=tmp_path / "teacher", cwd=tmp_path)
    assert done.returncode == 0 and (tmp_path / "curve" / "class_curve.csv").is_file(), done.stdout + done.stderr
