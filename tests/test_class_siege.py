"""The live class against one hostile laptop (issue 37): it cannot stop the class, crowd it or pose as a classmate.

Every client here is another machine than the teacher's: a loopback address from 127.0.0.2 up (Linux routes the
whole of 127.0.0.0/8 to this machine), while 127.0.0.1 is the teacher's own. Every attack is bounded in time
and count, and sent only to the class on loopback.
"""

from __future__ import annotations

import contextlib
import http.client
import http.server
import json
import os
import socket
import stat
import sys
import threading
import time

import pytest
from class_server import running_class, tapped_game

from armgame.classroom import app as class_app
from armgame.classroom import client
from armgame.classroom import state as class_state
from armgame.classroom.labruns import real_folder
from armgame.classroom.serve import open_class
from armgame.errors import UserError
from armgame.records.lookalikes import name_problem, skeletons

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="other machines are other loopback addresses on Linux")

LAPTOP, STUDENT, OTHER = "127.0.0.2", "127.0.0.3", "127.0.0.4"


@pytest.fixture
def opened(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as served:
        yield served


def state(opened) -> class_state.ClassState:
    return opened.server.config.app.state.armgame


def call(opened, method: str, path: str, body: bytes | None = None, headers: dict | None = None,
         source: str = STUDENT, timeout: float = 10):
    """(status, parsed JSON or text) of one request from ``source``, whatever the status."""
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=timeout, source_address=(source, 0))
    if method == "POST":
        headers = {"Content-Type": "application/json", **(headers or {})}
    try:
        conn.request(method, path, body=body, headers=headers or {})
        response = conn.getresponse()
        data = response.read()
    finally:
        conn.close()
    try:
        return response.status, json.loads(data)
    except ValueError:
        return response.status, data.decode("utf-8", "replace")


def join(opened, name: str, source: str = STUDENT, code: str | None = None, token: str | None = None):
    body = {"code": code or opened.clerk.roster.code, "name": name, **({"token": token} if token else {})}
    return call(opened, "POST", "/api/join", json.dumps(body).encode(), source=source)


def hand_in(opened, token: str, data: bytes, source: str = STUDENT):
    return call(opened, "POST", "/api/handin", data, {"Authorization": f"Bearer {token}",
                                                      "X-Armgame-Code": opened.clerk.roster.code}, source)


def sock_from(opened, source: str) -> socket.socket:
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.settimeout(10)
    s.bind((source, 0))
    s.connect(("127.0.0.1", opened.port))
    return s


def reply_of(s: socket.socket, within: float = 5) -> bytes:
    """What the server sends on ``s`` until it closes it (or ``within`` seconds pass)."""
    s.settimeout(within)
    reply = b""
    with contextlib.suppress(OSError):
        while chunk := s.recv(4096):
            reply += chunk
    return reply


def closed_by_server(s: socket.socket, within: float) -> bool:
    """Whether the server closes ``s`` within ``within`` seconds (reading whatever it sends first)."""
    s.settimeout(within)
    try:
        while s.recv(4096):
            pass
        return True
    except (ConnectionResetError, BrokenPipeError):
        return True
    except TimeoutError:
        return False


# ---------------------------------------------------------------------- connections that cost nothing to hold
def test_idle_sockets_from_one_laptop_cannot_stop_the_class(opened):
    held = []
    try:
        for _ in range(420):  # the issue's count: today's limit was 400 for everyone
            with contextlib.suppress(OSError):
                held.append(sock_from(opened, LAPTOP))
        started = time.perf_counter()
        status, _ = call(opened, "GET", "/api/standings")
        assert status == 200 and time.perf_counter() - started < 2
        assert join(opened, "Ann")[0] == 200
        assert sum(state(opened).guard.open.get(LAPTOP, 0) for _ in [0]) <= state(opened).guard.per_address
        assert state(opened).guard.refused >= 420 - state(opened).guard.per_address
    finally:
        for s in held:
            s.close()


def test_an_idle_or_trickling_connection_is_closed_at_its_deadline(opened):
    state(opened).guard.header_seconds = 0.6
    idle = sock_from(opened, LAPTOP)
    trickle = sock_from(opened, LAPTOP)
    started = time.perf_counter()
    with contextlib.suppress(OSError):
        for byte in b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ":
            trickle.send(bytes([byte]))
            time.sleep(0.05)
            if time.perf_counter() - started > 3:
                break
    assert closed_by_server(trickle, 3) and closed_by_server(idle, 3)
    assert time.perf_counter() - started < 5
    idle.close()
    trickle.close()


def test_a_kept_alive_or_pipelined_connection_has_the_same_deadline_for_its_next_request(opened):
    """Two requests in one packet get two answers; a third begun behind them and never finished, or none at all
    after an answer, is cut off at the header deadline counted from the answer (or from its first byte)."""
    state(opened).guard.header_seconds = 0.6
    get = b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"
    pipelined = sock_from(opened, LAPTOP)
    pipelined.sendall(get + get + b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
    kept = sock_from(opened, LAPTOP)
    kept.sendall(get)
    started = time.perf_counter()
    replies = reply_of(pipelined, 4), reply_of(kept, 4)
    assert time.perf_counter() - started < 3
    assert replies[0].count(b"HTTP/1.1 200") == 2 and replies[1].count(b"HTTP/1.1 200") == 1
    pipelined.close()
    kept.close()


def test_a_body_trickled_after_its_headers_is_cut_off(opened):
    state(opened).guard.request_seconds = 0.8
    s = sock_from(opened, LAPTOP)
    s.sendall(b"POST /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
              b"Content-Length: 100000\r\n\r\n{")  # a route that never reads a body: the connection's deadline cuts it
    started = time.perf_counter()
    with contextlib.suppress(OSError):
        while time.perf_counter() - started < 3:
            s.send(b" ")
            time.sleep(0.1)
    assert closed_by_server(s, 3) and time.perf_counter() - started < 4
    s.close()


def test_event_streams_have_a_share_per_machine_and_the_projector_always_gets_its_own(opened, monkeypatch):
    monkeypatch.setattr(class_app, "MAX_STREAMS", 6)
    streams = []

    def stream(source: str, path: str = "/events") -> int:
        conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=(source, 0))
        conn.request("GET", path)
        response = conn.getresponse()
        if response.status == 200:
            response.fp.readline()  # the first event's first line: the stream is open
        streams.append(conn)
        return response.status

    try:
        assert [stream(LAPTOP) for _ in range(6)] == [200] * class_app.STREAMS_PER_ADDRESS + [503, 503]
        assert [stream(OTHER) for _ in range(3)] == [200, 200, 503]  # the class's six places are taken
        key = opened.clerk.roster.projector_key()
        assert stream("127.0.0.9", f"/events?key={key}") == 200  # the projector's link: always
        assert stream("127.0.0.1") == 200  # the teacher's machine: always
    finally:
        for conn in streams:
            conn.close()


def test_slow_bodies_take_one_machines_share_of_uploads_not_the_class(opened):
    _, laptop = join(opened, "Mallory", LAPTOP)
    _, ann = join(opened, "Ann")
    slow = []
    try:
        replies = []
        for _ in range(8):
            s = sock_from(opened, LAPTOP)
            s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                      f"Authorization: Bearer {laptop['token']}\r\nX-Armgame-Code: {opened.clerk.roster.code}\r\n"
                      f"Content-Length: 4000\r\n\r\n{{".encode())
            slow.append(s)
        for s in slow[class_app.UPLOADS_PER_ADDRESS:]:  # past the machine's share: busy at once, body unread
            replies.append(reply_of(s))
        assert all(r.startswith(b"HTTP/1.1 503") and class_state.BUSY.encode() in r for r in replies), replies
        started = time.perf_counter()
        status, answer = hand_in(opened, ann["token"], tapped_game(5, player="Ann").to_bytes())
        assert status == 200 and answer["ok"] and time.perf_counter() - started < 5
    finally:
        for s in slow:
            s.close()


def test_a_wrong_token_is_refused_from_its_headers_before_its_body_is_read(opened):
    s = sock_from(opened, LAPTOP)
    s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
              f"Authorization: Bearer not-a-token\r\nX-Armgame-Code: {opened.clerk.roster.code}\r\n"
              f"Content-Length: 4000000\r\n\r\n{{".encode())
    reply = reply_of(s)  # answered with 3,999,999 bytes still to come
    assert reply.startswith(b"HTTP/1.1 401") and b"has not joined" in reply
    s.close()


# ---------------------------------------------------------------------- the code keeps strangers out
def test_nothing_a_stranger_fetches_carries_the_join_code(opened):
    code = opened.clerk.roster.code
    join(opened, "Ann")
    for path in ("/", "/lab", "/teacher", "/api/standings", "/api/lab", "/static/standings.js"):
        status, body = call(opened, "GET", path, source=LAPTOP)
        assert status == 200 and f"--code {code}" not in json.dumps(body), path
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=(LAPTOP, 0))
    conn.request("GET", "/events")
    response = conn.getresponse()
    first = response.fp.readline() + response.fp.readline()  # "event: standings", then its data
    conn.close()
    assert b"standings" in first and f"--code {code}".encode() not in first
    key = opened.clerk.roster.projector_key()
    for source, path in ((LAPTOP, f"/api/standings?key={key}"), ("127.0.0.1", "/api/standings")):
        assert call(opened, "GET", path, source=source)[1]["join"].endswith(f"--code {code}")
    assert call(opened, "GET", "/api/standings?key=" + "0" * 20, source=LAPTOP)[1]["join"] is None


def test_changes_come_as_json_from_the_class_own_pages_only(opened):
    body = json.dumps({"code": opened.clerk.roster.code, "name": "Ann"}).encode()
    for headers, status in (({"Content-Type": "text/plain"}, 415),
                            ({"Content-Type": "application/x-www-form-urlencoded"}, 415),
                            ({"Origin": "http://evil.example"}, 403),
                            ({"Origin": "null"}, 403),
                            ({"Sec-Fetch-Site": "cross-site"}, 403),
                            ({"Host": "evil.example"}, 421)):
        assert call(opened, "POST", "/api/join", body, headers)[0] == status, headers
    assert opened.clerk.roster.players == {} and not state(opened).codes.seen
    assert call(opened, "POST", "/api/join", body, {"Origin": f"http://127.0.0.1:{opened.port}"})[0] == 200


@pytest.mark.slow  # in chromium: CI's slow tier runs every page after the suite
def test_a_page_on_another_site_cannot_join_guess_or_lock_anyone_out(opened, tmp_path):
    from browser import browser_page

    hostile = (f'<!doctype html><script>const c = "http://127.0.0.1:{opened.port}/api/join";'
               f'for (let i = 0; i < 30; i++) {{'
               f'fetch(c, {{method: "POST", mode: "no-cors", headers: {{"Content-Type": "text/plain"}},'
               f' body: JSON.stringify({{code: "QQQQ", name: "Ann" + i}})}});'
               f'fetch(c, {{method: "POST", headers: {{"Content-Type": "application/json"}},'
               f' body: JSON.stringify({{code: "{opened.clerk.roster.code}", name: "Bo" + i}})}}).catch(() => 0);}}'
               f'document.title = "sent";</script>').encode()

    class Page(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.end_headers()
            self.wfile.write(hostile)

        def log_message(self, *args):
            pass

    site = http.server.ThreadingHTTPServer(("127.0.0.5", 0), Page)
    threading.Thread(target=site.serve_forever, daemon=True).start()
    try:
        with browser_page(1024, 768) as page:
            page.goto(f"http://127.0.0.5:{site.server_port}/")
            page.wait_for_function("document.title === 'sent'")
            time.sleep(1.0)  # the requests' answers
    finally:
        site.shutdown()
        site.server_close()
    assert opened.clerk.roster.players == {}
    assert not state(opened).codes.seen  # not one wrong code was counted against the student's machine
    assert join(opened, "Ann", "127.0.0.1")[0] == 200


def test_x_forwarded_for_is_not_believed(opened):
    for i in range(class_state.FREE_GUESSES):
        call(opened, "POST", "/api/join", json.dumps({"code": "QQQQ", "name": "x"}).encode(),
             {"X-Forwarded-For": f"10.0.0.{i}"}, source=LAPTOP)
    status, _ = call(opened, "POST", "/api/join", json.dumps({"code": "QQQQ", "name": "x"}).encode(),
                     {"X-Forwarded-For": "10.0.0.99"}, source=LAPTOP)
    assert status == 429 and set(state(opened).codes.seen) == {LAPTOP}


# ---------------------------------------------------------------------- lock-outs hit the guesser
def test_codes_secrets_and_tokens_are_counted_apart_and_the_teacher_is_never_locked_out(opened):
    for _ in range(class_state.FREE_GUESSES):
        call(opened, "GET", "/api/teacher/standings", headers={"Authorization": "Bearer wrong"}, source=LAPTOP)
    assert call(opened, "GET", "/api/teacher/standings", headers={"Authorization": "Bearer wrong"},
                source=LAPTOP)[0] == 429
    assert join(opened, "Mallory", LAPTOP)[0] == 200  # wrong secrets are not wrong codes
    for _ in range(3 * class_state.FREE_GUESSES):  # the teacher's machine is the teacher, whatever it sends
        assert call(opened, "GET", "/api/teacher/standings", headers={"Authorization": "Bearer wrong"},
                    source="127.0.0.1")[0] == 200
    secret = opened.clerk.roster.secret
    assert call(opened, "GET", "/api/teacher/standings", headers={"Authorization": f"Bearer {secret}"},
                source=OTHER)[0] == 200  # a colleague's machine with the secret
    for _ in range(class_state.FREE_GUESSES):
        hand_in(opened, "forged-token", b"{}", LAPTOP)
    assert hand_in(opened, "forged-token", b"{}", LAPTOP)[0] == 429
    assert join(opened, "Ann")[0] == 200  # a neighbour is not refused for the laptop's guesses


def test_the_wait_doubles_and_a_right_code_clears_it():
    now = [0.0]
    guesses = class_state.Guesses(free=3, wait=60.0, clock=lambda: now[0])
    for _ in range(3):
        guesses.failed("a")
    assert guesses.blocked_for("a") == 60.0 and not guesses.blocked("b")
    now[0] = 61.0
    guesses.failed("a")
    assert guesses.blocked_for("a") == 120.0
    guesses.succeeded("a")
    assert not guesses.blocked("a")
    # The docs' figure: from one address, the wrong codes an hour can try (5 free, then 1, 2, 4, 8... minutes).
    guesses, now[0], tries = class_state.Guesses(clock=lambda: now[0]), 0.0, 0
    while now[0] < 3600:
        now[0] += guesses.blocked_for("a") or 1.0
        if now[0] < 3600:
            guesses.failed("a")
            tries += 1
    assert tries == 10
    from armgame.classroom.roster import CODE_ALPHABET, CODE_LENGTH

    assert len(CODE_ALPHABET) ** CODE_LENGTH == 160_000


# ---------------------------------------------------------------------- a name is a person's
LOOKALIKES = [
    "Ann B\u034f", "Ann B\ufe0f", "Ann B\u3164", "Ann B\u2800", "Ann B\u17b4",  # trailing invisible characters
    "Ann \u0299", "\u0251nn B",  # a Latin small capital, a Latin alpha
    "A\u0578\u0578 B", "\u13aann B", "Ann \u13f4",  # Armenian and Cherokee letters
    "\u0410nn B", "Ann \u0412", "\u0391nn B", "Ann \u0392",  # Cyrillic and Greek capitals
    "ann b", "ANN B", "Ann  B", "\uff21\uff4e\uff4e \uff22", "Ann\u00a0B", "Ann\u2009B",  # case, spaces, full width
    "\u200bAnn B", "Ann B\u200d", "Ann\u2060 B", "Ann \U0001d401",  # zero-width, a mathematical bold B
]


def test_every_lookalike_of_a_taken_name_is_refused_and_real_names_join(opened):
    assert join(opened, "Ann B")[0] == 200
    for i, name in enumerate(LOOKALIKES):
        status, answer = join(opened, name, f"127.0.1.{i + 1}")
        assert status in (400, 409) and not answer["ok"], (name, answer)
    assert set(opened.clerk.roster.players) == {"ann b"}
    real = ("Zo\u00eb F", "Jos\u00e9", "\u0141ucja", "\u674e\u5c0f\u9f8d", "\u0414\u0430\u0440\u044c\u044f",
            "Nguy\u1ec5n V\u0103n An", "Ann C", "Eli", "Ell")
    for i, name in enumerate(real):
        status, answer = join(opened, name, f"127.0.2.{i + 1}")
        assert status == 200, (name, answer)


def test_the_name_rules_in_words():
    assert name_problem("Ann B\u3164") == "it holds an invisible character (U+3164)"
    assert name_problem("\u13aann") == "it mixes letters of Cherokee and Latin"
    assert name_problem("\u5c71\u7530 Yuki") is None  # Han with Latin: a Japanese name in two scripts
    assert name_problem("e" + "\u0301\u0302\u0303\u0304\u0306\u0307") is not None and name_problem("\u1ec7") is None
    assert skeletons("Ian") & skeletons("lan") and not skeletons("Eli") & skeletons("Ell")


def test_a_join_flood_from_one_machine_is_limited_seen_removed_and_the_list_locked(opened):
    answers = [join(opened, f"Bot {letter}", LAPTOP) for letter in "ABCDEFGH"]
    assert [s for s, _ in answers] == [200] * class_state.JOINS_PER_MINUTE + [429] * (8 - class_state.JOINS_PER_MINUTE)
    assert "one name a student" in answers[-1][1]["error"]
    _, ann = join(opened, "Ann")
    secret = {"Authorization": f"Bearer {opened.clerk.roster.secret}"}
    _, view = call(opened, "GET", "/api/teacher/roster", headers=secret, source="127.0.0.1")
    laptop = next(m for m in view["machines"] if m["address"] == LAPTOP)
    assert [n["name"] for n in laptop["names"]] == ["Bot A", "Bot B", "Bot C"]
    assert view["waiting"] == 4 and all(n["games"] == 0 for n in laptop["names"])  # joined, none played
    status, answer = call(opened, "POST", "/api/teacher/remove", json.dumps(
        {"names": [n["name"] for n in laptop["names"]]}).encode(), secret, "127.0.0.1")
    assert status == 200 and answer["message"].startswith("3 names removed")
    assert hand_in(opened, answers[0][1]["token"], tapped_game(1, player="Bot A").to_bytes(), LAPTOP)[0] == 401
    assert {"bot a", "bot b", "bot c"} <= opened.clerk.roster.hidden
    assert call(opened, "POST", "/api/teacher/lock", b'{"locked": true}', secret, "127.0.0.1")[0] == 200
    status, answer = join(opened, "Cleo", OTHER)
    assert status == 403 and "locked" in answer["error"]
    assert join(opened, "Ann", token=ann["token"])[0] == 200  # those in play on


# ---------------------------------------------------------------------- nothing escapes, nothing leaks
def test_a_lab_folder_planted_as_a_link_is_refused(tmp_path):
    outside = tmp_path / "outside"
    outside.mkdir()
    (tmp_path / "lab").symlink_to(outside, target_is_directory=True)
    with pytest.raises(UserError, match="not a folder"):
        real_folder(tmp_path / "lab")
    (tmp_path / "lab-more").write_text("x")
    with pytest.raises(UserError, match="not a folder"):
        real_folder(tmp_path / "lab-more")
    real_folder(tmp_path / "fresh")
    assert stat.S_ISDIR(os.lstat(tmp_path / "fresh").st_mode) and list(outside.iterdir()) == []


def test_the_lock_and_token_files_are_their_owners_and_two_servers_cannot_share_a_folder(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    folder = tmp_path / "class"
    with running_class(folder) as opened:
        member = client.join(client.ClassAddress.parse(f"127.0.0.1:{opened.port}"), opened.clerk.roster.code, "Ann")
        assert client.hand_in(member, tapped_game(2, player="Ann").to_bytes()).answer["ok"]
        with pytest.raises(UserError, match="another armgame class serve is serving"):
            open_class(folder, "127.0.0.1", 0, None, say=lambda line: None)
    for path in (folder / "scores.lock", folder / "server.lock", folder / "teacher.secret",
                 tmp_path / "machine" / "memberships.json"):
        assert stat.S_IMODE(os.stat(path).st_mode) == 0o600, path
    with running_class(folder):  # the first server gone, the folder is free again
        pass


def test_a_refusal_names_no_path_of_the_teachers_machine_and_a_failed_save_changes_nothing(opened, monkeypatch):
    from armgame.records.storage import DataFileError

    _, ann = join(opened, "Ann")
    hand_in(opened, ann["token"], tapped_game(4, player="Ann").to_bytes())

    def broken(self):
        raise DataFileError(f"{self.folder}/class.json: cannot write the class record: disk full")

    monkeypatch.setattr(type(opened.clerk.roster), "save", broken)
    secret = {"Authorization": f"Bearer {opened.clerk.roster.secret}"}
    for path, body in (("/api/teacher/hide", {"name": "Ann"}), ("/api/teacher/close", {"closed": True}),
                       ("/api/teacher/lock", {"locked": True}), ("/api/teacher/remove", {"names": ["Ann"]}),
                       ("/api/teacher/release", {"name": "Ann"})):
        status, answer = call(opened, "POST", path, json.dumps(body).encode(), secret, "127.0.0.1")
        assert status == 503 and str(opened.clerk.folder) not in answer["error"], (path, answer)
    status, answer = join(opened, "Bo")
    assert status == 503 and str(opened.clerk.folder) not in answer["error"]
    roster = opened.clerk.roster
    assert (roster.hidden, roster.closed, roster.locked, set(roster.players)) == (set(), False, False, {"ann"})
    assert roster.player_of(ann["token"]) is not None and roster.lookalike_of("Bo") is None


def test_the_class_stops_at_once_with_pages_open_and_says_nothing_more(tmp_path, capfd):
    ready = threading.Event()
    opened = open_class(tmp_path / "class", "127.0.0.1", 0, None, say=lambda line: None,
                        on_ready=lambda _: ready.set())
    thread = threading.Thread(target=opened.run, daemon=True)
    thread.start()
    assert ready.wait(20)
    pages = []
    for source in (LAPTOP, OTHER, "127.0.0.1"):
        conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=(source, 0))
        conn.request("GET", "/events")
        conn.getresponse().fp.readline()
        pages.append(conn)
    started = time.perf_counter()
    opened.stop()
    thread.join(10)
    assert not thread.is_alive() and time.perf_counter() - started < 1.5
    for conn in pages:
        conn.close()
    captured = capfd.readouterr()
    assert "Traceback" not in captured.err and "Cancel" not in captured.err, captured.err


def test_the_guide_states_the_class_limits_as_they_are():
    from pathlib import Path

    from armgame.classroom import guard

    guide = (Path(__file__).resolve().parent.parent / "docs" / "teaching.md").read_text(encoding="utf-8")
    section = guide.split("## One student with a script and a grudge", 1)[1].split("\n## ", 1)[0]
    for claim in (f"headers must arrive within {guard.HEADER_SECONDS:g} s",
                  f"whole request within {guard.REQUEST_SECONDS:g} s",
                  f"one machine holds at most {guard.PER_ADDRESS}",
                  f"{class_app.STREAMS_PER_ADDRESS} of the projector's live pages",
                  f"{class_app.UPLOADS_PER_ADDRESS} hand-ins being uploaded",
                  f"{class_state.FREE_GUESSES} free, then a wait of {class_state.GUESS_WAIT / 60:g} minute",
                  "10 tries an hour",  # test_the_wait_doubles_and_a_right_code_clears_it counts them
                  f"at most {class_state.JOINS_PER_MINUTE} new names a minute (the class",
                  f"{class_state.CLASS_JOINS_PER_MINUTE})"):
        assert claim in " ".join(section.split()), claim
