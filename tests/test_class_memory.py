"""The live class against the next laptop (issue 54): what one connection can make the server hold, upload places a
few machines cannot take, and sockets that cannot keep the teacher's machine or the projector out.

As in ``test_class_siege.py``, every other machine is a loopback address from 127.0.0.2 up, 127.0.0.1 the
teacher's own; each attack is bounded in count and time, and sent only to the class on loopback. What the server
holds is counted on its connections (queued requests, bytes held back), not read from its memory.
"""

from __future__ import annotations

import contextlib
import http.client
import json
import socket
import sys
import threading
import time

import pytest
from class_server import running_class, tapped_game

from armgame.classroom import client, guard, serve
from armgame.classroom import state as class_state

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="other machines are other loopback addresses on Linux")

LAPTOP, STUDENT = "127.0.0.2", "127.0.0.3"
GET = b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"


@pytest.fixture
def opened(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as served:
        yield served


def the_guard(opened) -> guard.Guard:
    return opened.server.config.app.state.armgame.guard


def connections_from(opened, address: str) -> list:
    return [p for p in list(opened.server.server_state.connections) if p.client and p.client[0] == address]


def call(opened, method: str, path: str, body: bytes | None = None, headers: dict | None = None,
         source: str = STUDENT, timeout: float = 5) -> tuple[int, object]:
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=timeout, source_address=(source, 0))
    if method == "POST":
        headers = {"Content-Type": "application/json", **(headers or {})}
    try:
        conn.request(method, path, body=body, headers=headers or {})
        response = conn.getresponse()
        data = response.read()
    finally:
        conn.close()
    with contextlib.suppress(ValueError):
        return response.status, json.loads(data)
    return response.status, data


def join(opened, name: str, source: str) -> str:
    status, answer = call(opened, "POST", "/api/join", json.dumps({"code": opened.clerk.roster.code,
                                                                   "name": name}).encode(), source=source)
    assert status == 200, answer
    return answer["token"]  # type: ignore[index]


def sock_from(opened, source: str) -> socket.socket:
    s = socket.create_connection(("127.0.0.1", opened.port), timeout=5, source_address=(source, 0))
    return s


def refusal_of(opened, head: bytes, header: bytes, count: int, seconds: float = 2.0) -> tuple[bytes, int]:
    """(what the server answered, bytes sent) to a request of ``head`` then ``header`` ``count`` times, sent from
    the laptop as fast as the server reads it and until it answers (or ``seconds`` pass)."""
    s = sock_from(opened, LAPTOP)
    answered = threading.Event()
    sent = [0]

    def send() -> None:
        with contextlib.suppress(OSError):
            s.sendall(head)
            batch = header * max(1, 65536 // len(header))
            until = time.monotonic() + seconds
            while sent[0] < count * len(header) and not answered.is_set() and time.monotonic() < until:
                s.sendall(batch)
                sent[0] += len(batch)

    sender = threading.Thread(target=send, daemon=True)
    sender.start()
    reply = b""
    s.settimeout(seconds + 1)
    with contextlib.suppress(OSError):
        while chunk := s.recv(4096):
            reply += chunk
            answered.set()
    answered.set()
    sender.join(5)
    s.close()
    return reply, sent[0]


# ---------------------------------------------------------------------- what one connection can make it hold
def test_a_pipelined_flood_is_answered_as_far_as_its_queue_and_closed(opened):
    """Four connections each pipeline 20,000 requests (1 MB) in one go and read nothing: each is answered its
    first request and the queue behind it, then closed; the class answers others at once meanwhile."""
    socks = []
    for _ in range(4):
        s = sock_from(opened, LAPTOP)
        s.setblocking(False)
        with contextlib.suppress(BlockingIOError):
            s.send(GET * 20_000)
        socks.append(s)
    try:
        started = time.perf_counter()
        assert call(opened, "GET", "/api/standings")[0] == 200 and time.perf_counter() - started < 1
        answered = []
        for s in socks:
            s.setblocking(True)
            s.settimeout(4)
            reply = b""
            with contextlib.suppress(OSError):
                while chunk := s.recv(65536):
                    reply += chunk
            answered.append(reply.count(b"HTTP/1.1 200"))
        assert min(answered) >= 1 and max(answered) <= 9, answered  # 1 + guard.PIPELINE
        assert guard.PIPELINE == 8
        assert not connections_from(opened, LAPTOP) and the_guard(opened).deepest <= guard.PIPELINE
    finally:
        for s in socks:
            s.close()


def test_requests_pipelined_behind_an_endless_answer_pause_reading_and_are_closed(opened):
    """Behind the projector's endless stream, a client sends request after request and reads nothing: at most
    the queue's requests wait and one read of input is held (reading is paused); the connection is closed when
    the queue has not moved for the request deadline, and the stream's app hears of it."""
    the_guard(opened).request_seconds = 1.0
    s = sock_from(opened, LAPTOP)
    s.sendall(b"GET /events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
    time.sleep(0.1)
    with contextlib.suppress(OSError):
        for _ in range(60):
            s.sendall(GET)
            time.sleep(0.002)
    time.sleep(0.2)
    assert len(connections_from(opened, LAPTOP)) == 1
    started = time.perf_counter()
    s.settimeout(4)
    with contextlib.suppress(OSError):
        while s.recv(65536):
            pass
    assert time.perf_counter() - started < 2
    s.close()
    state = opened.server.config.app.state.armgame
    deadline = time.monotonic() + 2
    while state.streams and time.monotonic() < deadline:
        time.sleep(0.05)
    assert state.streams == 0 and not state.streaming and not connections_from(opened, LAPTOP)
    assert the_guard(opened).deepest <= guard.PIPELINE


def test_a_pipelining_client_is_paused_then_answered_in_full(opened):
    """30 requests of 1 KiB pipelined in one go: the queue fills, the rest of the input is held back (one read at
    most) until answers are written, and all 30 are answered."""
    s = sock_from(opened, LAPTOP)
    request = GET[:-2] + b"X-Pad: " + b"p" * 1000 + b"\r\n\r\n"
    s.sendall(b"".join(request.replace(b"standings", b"standings?n=%d" % i) for i in range(30)))
    reply = b""
    with contextlib.suppress(OSError):  # (a half-closed connection would end the queue: uvicorn closes at EOF)
        while reply.count(b"HTTP/1.1 200") < 30 and (chunk := s.recv(65536)):
            reply += chunk
    s.close()
    assert reply.count(b"HTTP/1.1 200") == 30
    assert the_guard(opened).deepest == guard.PIPELINE and 0 < the_guard(opened).held_most <= 256 * 1024


def test_a_six_million_header_request_is_refused_at_its_101st_header(opened):
    reply, sent = refusal_of(opened, b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\n", b"a:b\r\n", 6_300_000)
    assert reply.startswith(b"HTTP/1.1 431"), reply[:200]
    assert f"more than {guard.MAX_HEADERS} headers".encode() in reply
    assert sent < 6_300_000 * 5 and the_guard(opened).too_large == 1


def test_a_16_mib_header_block_is_refused_and_a_large_honest_one_is_not(opened):
    reply, _ = refusal_of(opened, b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Big: ", b"a" * 1024,
                          16 * 1024)
    assert reply.startswith(b"HTTP/1.1 431"), reply[:200]
    assert f"longer than {guard.MAX_HEADER_BYTES:,} bytes".encode() in reply
    one_value, _ = refusal_of(opened, b"GET /api/standings HTTP/1.1\r\nHost: 127.0.0.1\r\n",
                              b"X-Many: 12345678901234567890\r\n", 20_000)  # 600 KB of headers under the count
    assert one_value.startswith(b"HTTP/1.1 431")
    cookie = {"Cookie": "c=" + "x" * 12_000, **{f"X-H{i}": "v" for i in range(80)}}
    assert call(opened, "GET", "/api/standings", headers=cookie)[0] == 200


# ---------------------------------------------------------------------- places a few machines cannot take
def test_trickled_hand_ins_from_40_machines_leave_an_honest_one_answered_at_once(opened):
    """40 machines, each with its name, hold an upload place (one a player at once) with a body sent a byte at a
    time, 40 more places than the class had in all; an honest student's game is acknowledged within 2 s."""
    machines = [f"127.0.3.{i}" for i in range(1, 41)]
    tokens = {m: join(opened, f"Bot {i}", m) for i, m in enumerate(machines)}
    ann = join(opened, "Ann", STUDENT)
    code = opened.clerk.roster.code
    slow = []
    try:
        for machine in machines:
            for _ in range(class_state.TOKEN_SHARE):
                s = sock_from(opened, machine)
                s.sendall(f"POST /api/handin HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                          f"Authorization: Bearer {tokens[machine]}\r\nX-Armgame-Code: {code}\r\n"
                          f"Content-Length: 9000\r\n\r\n{{".encode())
                slow.append(s)
        state = opened.server.config.app.state.armgame
        deadline = time.monotonic() + 3
        while sum(state.uploading.values()) < len(slow) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert sum(state.uploading.values()) == len(slow) == 40 > class_state.UPLOADS
        started = time.perf_counter()
        status, answer = call(opened, "POST", "/api/handin", tapped_game(5, player="Ann").to_bytes(),
                              {"Authorization": f"Bearer {ann}", "X-Armgame-Code": code})
        assert status == 200 and answer["ok"] and time.perf_counter() - started < 2  # type: ignore[index]
    finally:
        for s in slow:
            s.close()


def test_no_number_of_addresses_keeps_the_teacher_or_the_projector_out(opened):
    """Addresses without number (IPv6 gives a laptop millions) each hold their share of idle sockets, past the
    class's limit (made small here: 30 other machines' connections, 40 in all): the teacher's machine and the
    projector's link still get in, and the one past the limit is told the class is full."""
    the_guard(opened).connections = 30
    the_guard(opened).probation = 4
    opened.server.config.limit_concurrency = 40
    held = []
    try:
        for i in range(12):
            for _ in range(6):
                with contextlib.suppress(OSError):
                    held.append(sock_from(opened, f"127.0.4.{i + 1}"))
        time.sleep(0.2)
        assert call(opened, "GET", "/api/standings", source="127.0.0.1")[0] == 200
        assert call(opened, "GET", "/api/teacher/roster", source="127.0.0.1")[0] == 200
        status, answer = call(opened, "GET", f"/api/standings?key={opened.clerk.roster.projector_key()}",
                              source="127.0.0.9")
        assert status == 200 and answer["join"]  # type: ignore[index]
        assert call(opened, "GET", "/api/standings", source="127.0.0.8")[0] == 503
        assert the_guard(opened).others <= 30 and len(the_guard(opened).waiting) <= 4
    finally:
        for s in held:
            s.close()


def test_the_guide_states_the_new_bounds_and_the_reserve_holds():
    from pathlib import Path

    assert serve.CONCURRENCY - guard.CONNECTIONS >= guard.PROBATION + 64  # room for the teacher's machine
    guide = (Path(__file__).resolve().parent.parent / "docs" / "teaching.md").read_text(encoding="utf-8")
    section = " ".join(guide.split("## One student with a script and a grudge", 1)[1].split("\n## ", 1)[0].split())
    for claim in (f"at most {guard.PIPELINE} requests wait", f"{guard.MAX_HEADERS} headers",
                  f"{guard.MAX_HEADER_BYTES // 1024} KiB of headers", f"has {class_state.SMALL_UPLOADS} places",
                  f"{guard.CONNECTIONS:,} connections", f"apart from the {class_state.UPLOADS} for large",
                  f"closes it if they stop going out for {guard.REQUEST_SECONDS:g} s"):
        assert claim in section, claim
