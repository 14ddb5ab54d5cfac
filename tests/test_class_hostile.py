"""The live class against the classmate at the next desk: every request hostile until checked, refused in one
line, bounded in what it can cost, and nothing but the class's folder written."""

from __future__ import annotations

import contextlib
import csv
import http.client
import io
import json
import logging
import socket
import threading
import time
import urllib.request

import pytest
from class_server import keyboard_game, running_class, tapped_game, tapped_games

from armgame.classroom import app as class_app
from armgame.classroom import client, views
from armgame.classroom import state as class_state
from armgame.classroom.roster import Roster


@pytest.fixture
def opened(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as served:
        yield served


def call(opened, method: str, path: str, body: bytes | None = None, headers: dict | None = None,
         source: str | None = None):
    """(status, parsed JSON or text) of one request, whatever the status; from ``source`` (another loopback
    address, 127.0.0.2 and up: another machine than the teacher's) if given."""
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=20,
                                      source_address=(source, 0) if source else None)
    if method == "POST":  # the class's own client's and pages' way: JSON, said so
        headers = {"Content-Type": "application/json", **(headers or {})}
    conn.request(method, path, body=body, headers=headers or {})
    response = conn.getresponse()
    data = response.read()
    conn.close()
    try:
        return response.status, json.loads(data)
    except ValueError:
        return response.status, data.decode("utf-8", "replace")


def join(opened, name: str, code: str | None = None, source: str | None = None):
    return call(opened, "POST", "/api/join", json.dumps({"code": code or opened.clerk.roster.code,
                                                         "name": name}).encode(),
                {"Content-Type": "application/json"}, source)


def test_a_wrong_code_is_refused_and_guessing_stops_the_guesser_only(opened):
    status, answer = join(opened, "Ann", "QQQQ", source="127.0.0.2")
    assert status == 403 and answer == {"ok": False, "error": "wrong class code: check the code on the projector"}
    for _ in range(class_state.FREE_GUESSES - 1):
        join(opened, "Ann", "QQQQ", source="127.0.0.2")
    status, answer = join(opened, "Ann", source="127.0.0.2")  # while it waits, no answer of its is looked at
    assert status == 429 and "too many wrong codes" in answer["error"] and "wait 60 s" in answer["error"]
    assert opened.clerk.roster.players == {}
    status, answer = join(opened, "Ben", source="127.0.0.3")  # the neighbour with the right code: at once
    assert status == 200 and answer["name"] == "Ben"


def test_bad_bodies_are_refused_in_one_line_and_nothing_is_entered(opened):
    for body, why in ((b"{not json", "not JSON"), (b"[1, 2]", "JSON object"), (b'{"code": 5}', "wrong class code"),
                      (b"x" * 5000, "larger than a class takes")):
        status, answer = call(opened, "POST", "/api/join", body, {"Content-Type": "application/json"})
        assert status in (400, 403, 413) and why in answer["error"] and "\n" not in answer["error"]
    status, answer = join(opened, "Ann")
    token = answer["token"]
    headers = {"Authorization": f"Bearer {token}", "X-Armgame-Code": opened.clerk.roster.code}
    for body, why in ((b"\xff\xfe", "not a text file"), (b'{"format": "armgame-replay"}', "replay"),
                      (b"[]", "not an armgame replay")):
        status, answer = call(opened, "POST", "/api/handin", body, headers)
        assert status == 400 and why in answer["error"] and "\n" not in answer["error"], answer
    status, answer = call(opened, "POST", "/api/handin", keyboard_game(5, player="Ann").to_bytes(),
                          {"X-Armgame-Code": opened.clerk.roster.code, "Authorization": "Bearer forged"})
    assert status == 401 and "join first" in answer["error"]
    status, answer = call(opened, "POST", "/api/handin", b"{}", {**headers, "Content-Length": str(10**9)})
    assert status == 413
    assert opened.clerk.entries == []


def test_a_body_over_the_limit_is_cut_off_as_it_arrives_and_a_slow_one_in_time(opened, monkeypatch):
    _status, answer = join(opened, "Ann")
    headers = {"Authorization": f"Bearer {answer['token']}", "X-Armgame-Code": opened.clerk.roster.code}
    monkeypatch.setattr(class_app, "MAX_HANDIN_BYTES", 200_000)  # the same cut, sooner
    # No declared length, and far more than the limit: the server stops reading once past it and closes
    # the connection, so the sender is cut off long before it has sent it all (or reads the 413 first).
    sent, reply = 0, b""
    with socket.create_connection(("127.0.0.1", opened.port), timeout=20) as s:
        s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                  f"Transfer-Encoding: chunked\r\nX-Armgame-Code: "
                  f"{headers['X-Armgame-Code']}\r\nAuthorization: {headers['Authorization']}\r\n\r\n".encode())
        with contextlib.suppress(OSError):
            for _ in range(1000):  # 64 MB
                s.sendall(b"10000\r\n" + b"x" * 65536 + b"\r\n")
                sent += 1
        with contextlib.suppress(OSError):
            while chunk := s.recv(4096):
                reply += chunk
    assert sent < 1000 or reply.startswith(b"HTTP/1.1 413")
    assert not reply or (reply.startswith(b"HTTP/1.1 413") and b"larger than a class takes" in reply)
    assert join(opened, "Bo")[0] == 200  # and the class goes on
    assert opened.clerk.entries == []
    monkeypatch.setattr(class_app, "BODY_SECONDS", 0.3)
    with socket.create_connection(("127.0.0.1", opened.port), timeout=20) as s:
        s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                  f"Content-Length: 1000\r\nX-Armgame-Code: "
                  f"{opened.clerk.roster.code}\r\nAuthorization: Bearer {answer['token']}\r\n\r\n{{".encode())
        reply = b""
        while chunk := s.recv(4096):
            reply += chunk
        reply = reply.decode()
    assert reply.startswith("HTTP/1.1 408") and "took longer than 0.3 s" in reply


def test_hostile_names_are_data_everywhere(opened):
    names = ['<script>alert("x")</script>', "=HYPERLINK(\"http://x\")", "+1 \"quoted\" 'name'", "\u0639\u0644\u064a"]
    tokens = {}
    for name in names:
        status, answer = join(opened, name)
        assert status == 200, answer
        tokens[name] = answer["token"]
    for bad in ("Ann\u202eevil", "", " " * 3, "x" * 41, "line\nbreak"):
        status, answer = join(opened, bad)
        assert status == 400 and "name" in answer["error"], (bad, answer)
    code = opened.clerk.roster.code
    for i, name in enumerate(names):
        status, answer = call(opened, "POST", "/api/handin", tapped_game(i, player=name).to_bytes(),
                              {"Authorization": f"Bearer {tokens[name]}", "X-Armgame-Code": code})
        assert status == 200, answer
    status, standings = call(opened, "GET", "/api/standings")
    assert {r["name"] for r in standings["students"]} == set(names)  # as typed, for the page to set as text
    status, text = call(opened, "GET", "/api/teacher/games.csv", headers={
        "Authorization": f"Bearer {opened.clerk.roster.secret}"})
    assert text.startswith("\ufeffentered,")  # a spreadsheet reads it as UTF-8: an accented name stays whole
    rows = {r["name"] for r in csv.DictReader(io.StringIO(text.removeprefix("\ufeff")))}
    assert all(len(r["entered_local"]) == 19 for r in csv.DictReader(io.StringIO(text.removeprefix("\ufeff"))))
    assert "'=HYPERLINK(\"http://x\")" in rows and "'+1 \"quoted\" 'name'" in rows  # never a formula
    assert '<script>alert("x")</script>' in rows
    status, page = call(opened, "GET", "/")
    assert "script-src 'self'" in urllib.request.urlopen(f"http://127.0.0.1:{opened.port}/").headers[
        "Content-Security-Policy"]
    assert "<script>alert" not in page  # the page holds no data: its script fetches it and sets it as text


def test_the_teachers_actions_need_the_secret_on_another_machine(opened):
    status, answer = join(opened, "Ann")
    code, token = opened.clerk.roster.code, answer["token"]
    call(opened, "POST", "/api/handin", tapped_game(3, player="Ann").to_bytes(),
         {"Authorization": f"Bearer {token}", "X-Armgame-Code": code})
    other = "127.0.0.2"  # a classmate's laptop; 127.0.0.1 is the teacher's own, which needs no secret
    for path, body in (("/api/teacher/hide", b'{"name": "Ann"}'), ("/api/teacher/close", b'{"closed": true}')):
        for headers in ({}, {"Authorization": "Bearer guessed"}):
            status, answer = call(opened, "POST", path, body, headers, other)
            assert status == 403 and "teacher's secret" in answer["error"]
    for path in ("/api/teacher/games.csv", "/api/teacher/lab.csv", "/api/teacher/standings"):
        assert call(opened, "GET", path, source=other)[0] in (403, 429)
    assert call(opened, "GET", "/api/standings")[1]["students"][0]["name"] == "Ann"
    assert opened.clerk.roster.secret not in call(opened, "GET", "/teacher")[1]
    secret = {"Authorization": f"Bearer {opened.clerk.roster.secret}"}
    assert call(opened, "POST", "/api/teacher/hide", b'{"name": "Ann"}', secret, "127.0.0.3")[0] == 200
    assert call(opened, "GET", "/api/standings")[1]["students"] == []  # hidden from the projector
    assert len(opened.clerk.entries) == 1  # and still in the table
    assert call(opened, "POST", "/api/teacher/close", b'{"closed": true}', secret)[0] == 200
    status, answer = call(opened, "POST", "/api/handin", tapped_game(4, player="Ann").to_bytes(),
                          {"Authorization": f"Bearer {token}", "X-Armgame-Code": code})
    assert status == 403 and "closed" in answer["error"]


def test_paths_from_a_client_are_never_used(opened, tmp_path):
    for path in ("/static/../class.json", "/static/teacher.secret", "/static/%2e%2e%2fclass.json", "/../class.json"):
        status, body = call(opened, "GET", path)
        assert status == 404 and "armgame-class" not in str(body)
    status, answer = join(opened, "../../escape")
    call(opened, "POST", "/api/handin", tapped_game(7, player="../../escape").to_bytes(),
         {"Authorization": f"Bearer {answer['token']}", "X-Armgame-Code": opened.clerk.roster.code})
    written = {p.relative_to(tmp_path).parts[0] for p in tmp_path.rglob("*")}
    assert written <= {"class", "machine"} and not list((tmp_path / "class").rglob("*escape*.json"))[0:0]
    assert all(".." not in p.name for p in (tmp_path / "class").rglob("*"))


def test_a_hit_storm_is_refused_before_it_is_replayed(opened):
    status, answer = join(opened, "Ann")
    replay = json.loads(keyboard_game(5, player="Ann").to_bytes())
    replay["result"]["hits"] = replay["result"]["score"] = 100_000
    started = time.perf_counter()
    status, answer = call(opened, "POST", "/api/handin", json.dumps(replay).encode(),
                          {"Authorization": f"Bearer {answer['token']}", "X-Armgame-Code": opened.clerk.roster.code})
    assert status == 413 and "more to check" in answer["error"] and time.perf_counter() - started < 5


def test_a_flood_is_queued_and_refused_politely_and_nothing_is_lost(tmp_path, monkeypatch):
    """50 machines hand in at once into a queue of 4 and 2 upload slots: some are asked to come back
    (503), their clients ask again, and every game is entered once."""
    monkeypatch.setattr(class_state, "QUEUE_LIMIT", 4)
    monkeypatch.setattr(class_state, "HANDIN_QUEUE", 4)
    monkeypatch.setattr(class_state, "UPLOADS", 2)
    monkeypatch.setattr(client, "_retry_after", lambda value: 0.05)
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    busy = []
    real = client._request

    with running_class(tmp_path / "class") as served:
        address = client.ClassAddress.parse(f"127.0.0.1:{served.port}")
        members = [client.join(address, served.clerk.roster.code, f"m{i}") for i in range(50)]
        games = tapped_games(50, [f"m{i}" for i in range(50)])
        results: list = [None] * 50
        original_sleep = time.sleep

        def student(i: int) -> None:
            results[i] = client.hand_in(members[i], games[i], keep=False)

        monkeypatch.setattr(client, "_request", lambda *a, **k: real(*a, **k, sleep=lambda s: (busy.append(s),
                                                                                           original_sleep(s))))
        threads = [threading.Thread(target=student, args=(i,)) for i in range(50)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(60)
        assert len(served.clerk.entries) == 50
    assert all(r is not None and r.answer is not None for r in results)
    assert busy  # some were told the class was busy, and came back


def test_a_failure_inside_the_class_is_one_line_and_the_class_goes_on(opened, monkeypatch, capsys):
    def broken(clerk, teacher: bool = False):
        raise RuntimeError("a bug")

    monkeypatch.setattr(views, "standings", broken)
    status, answer = call(opened, "GET", "/api/teacher/standings",
                          headers={"Authorization": f"Bearer {opened.clerk.roster.secret}"})
    assert status == 500 and "nothing was entered" in answer["error"]
    assert capsys.readouterr().err.strip() == "armgame class: GET /api/teacher/standings: RuntimeError: a bug"
    monkeypatch.undo()
    assert join(opened, "Ann")[0] == 200


def test_a_full_class_does_not_flood_the_teachers_terminal(opened):
    """uvicorn's "Exceeded concurrency limit.", a line for every connection past its limit (thousands when a lecture
    hall hands in at once), is not printed; its other warnings are."""
    logger = logging.getLogger("uvicorn.error")

    def warning(message: str) -> logging.LogRecord:
        return logging.LogRecord("uvicorn.error", logging.WARNING, __file__, 1, message, None, None)

    assert not logger.filter(warning("Exceeded concurrency limit."))
    assert logger.filter(warning("Invalid HTTP request received."))


def test_the_teacher_frees_a_name_for_a_students_new_machine(opened):
    """Ann's laptop fails: another machine cannot take her name until the teacher frees it; then her new machine
    joins under it and hands in, the old one no longer can, and her games stay one row of hers."""
    code, secret = opened.clerk.roster.code, {"Authorization": f"Bearer {opened.clerk.roster.secret}"}
    old = join(opened, "Ann")[1]["token"]
    assert call(opened, "POST", "/api/handin", tapped_game(3, player="Ann").to_bytes(),
                {"Authorization": f"Bearer {old}", "X-Armgame-Code": code})[0] == 200
    status, answer = join(opened, "ann")  # the new laptop, the name typed in another case
    assert status == 409 and "taken" in answer["error"]
    student = {"Authorization": f"Bearer {old}"}
    status, answer = call(opened, "POST", "/api/teacher/release", b'{"name": "Ann"}', student, "127.0.0.2")
    assert status == 403 and "teacher's secret" in answer["error"]  # a student's machine cannot free names
    status, answer = call(opened, "POST", "/api/teacher/release", b'{"name": "Bob"}', secret)
    assert status == 404 and "no machine" in answer["error"]
    assert call(opened, "POST", "/api/teacher/release", b'{"name": 7}', secret)[0] == 400
    status, answer = call(opened, "POST", "/api/teacher/release", b'{"name": "ANN"}', secret)
    assert status == 200 and "Ann is free" in answer["message"]
    status, answer = join(opened, "Ann")
    assert status == 200 and answer["token"] != old
    new = answer["token"]
    status, answer = call(opened, "POST", "/api/handin", tapped_game(4, player="Ann").to_bytes(),
                          {"Authorization": f"Bearer {old}", "X-Armgame-Code": code})
    assert status == 401  # the failed laptop, back from the dead, hands in nothing under her name
    assert call(opened, "POST", "/api/handin", tapped_game(5, player="Ann").to_bytes(),
                {"Authorization": f"Bearer {new}", "X-Armgame-Code": code})[0] == 200
    students = call(opened, "GET", "/api/standings")[1]["students"]
    assert [(r["name"], r["games"]) for r in students] == [("Ann", 2)]
    assert Roster.open(opened.clerk.roster.folder, None)[0].player_of(new).name == "Ann"  # kept on disk


def test_a_lookalike_of_a_taken_name_is_the_taken_name(opened):
    """A classmate joining as "\u0410nn" (a Cyrillic A) or "Ann  " with extra spaces is refused: on the projector it
    would read as Ann."""
    assert join(opened, "Ann B")[0] == 200
    for lookalike in ("\u0410nn B", "ann   b", "\u0391NN B"):
        status, answer = join(opened, lookalike)
        assert status == 409 and "taken" in answer["error"], lookalike


def test_a_class_from_before_lookalikes_counted_goes_on(tmp_path):
    """class.json written under the older keys (inner spaces kept, lookalikes apart) opens, each player under
    today's key, the first to join keeping a name two of them now share, hidden names still hidden."""
    from armgame.classroom.roster import Player
    from armgame.records.standings import legacy_player_key

    roster, _ = Roster.open(tmp_path, None)
    for name in ("Ann  B", "\u0410nn B", "Bo"):
        roster.players[legacy_player_key(name)] = Player(name, "a" * 64, "2026-11-25T09:00:00+00:00")
    roster.hidden = {legacy_player_key("Bo"), legacy_player_key("\u0410nn B")}
    roster.save()
    again, new = Roster.open(tmp_path, None)
    assert not new and sorted(again.players) == ["ann b", "bo"] and again.players["ann b"].name == "Ann  B"
    assert again.is_hidden("Bo") and again.is_hidden("Ann B")
