"""The class's app in Starlette's shape: the security headers on every answer (the middleware's, said once), the
same-site check on the class's own routes only, and the clerk's thread taking its work in order, hand-ins that
wait together entered as one batch."""

from __future__ import annotations

import http.client
import threading

import pytest
from class_server import running_class, tapped_game

from armgame.classroom import client, views
from armgame.classroom.intake import Clerk
from armgame.classroom.middleware import SECURITY_HEADERS
from armgame.classroom.roster import Roster
from armgame.classroom.worker import ClerkThread


@pytest.fixture
def opened(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))
    with running_class(tmp_path / "class") as served:
        yield served


def raw(opened, method: str, path: str, body: bytes | None = None, headers: dict | None = None):
    """(status, the answer's headers as sent, in order) of one request from another machine than the teacher's."""
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=("127.0.0.2", 0))
    try:
        conn.request(method, path, body=body, headers=headers or {})
        response = conn.getresponse()
        if path != "/events":
            response.read()
        return response.status, [(k.lower(), v) for k, v in response.getheaders()]
    finally:
        conn.close()


def test_every_answer_carries_the_security_headers_once(opened, monkeypatch):
    def broken(clerk, teacher=False):
        raise RuntimeError("a bug")

    monkeypatch.setattr(views, "standings", broken)
    answers = {"page": raw(opened, "GET", "/"), "data": raw(opened, "GET", "/api/standings"),
               "stream": raw(opened, "GET", "/events"),
               "refused": raw(opened, "POST", "/api/join", b"{}", {"Content-Type": "text/plain"}),
               "bug": raw(opened, "GET", "/api/teacher/standings", headers={
                   "Authorization": f"Bearer {opened.clerk.roster.secret}"}),
               "no such path": raw(opened, "GET", "/nowhere"), "no such method": raw(opened, "GET", "/api/join")}
    assert {what: status for what, (status, _) in answers.items()} == {
        "page": 200, "data": 200, "stream": 200, "refused": 415, "bug": 500, "no such path": 404,
        "no such method": 405}
    for what, (_, headers) in answers.items():
        for name, value in SECURITY_HEADERS.items():
            assert [v for k, v in headers if k == name.lower()] == [value], (what, name)
    # Where the answers set theirs, as they always did: the refusal's, and the stream's.
    assert ("connection", "close") in answers["refused"][1]
    assert ("x-accel-buffering", "no") in answers["stream"][1]


def test_a_path_or_a_method_the_class_does_not_serve_stays_the_routers_own_answer(opened):
    """The same-site check is the class's routes' own (``middleware.SameSite`` on each): a foreign Host or a body
    that is not JSON is refused there, and only there."""
    assert raw(opened, "GET", "/", headers={"Host": "evil.example"})[0] == 421
    assert raw(opened, "GET", "/nowhere", headers={"Host": "evil.example"})[0] == 404
    assert raw(opened, "POST", "/api/join", b"{}", {"Content-Type": "text/plain"})[0] == 415
    assert raw(opened, "POST", "/", b"{}", {"Content-Type": "text/plain"})[0] == 405


def test_the_clerks_thread_takes_its_work_in_order_and_enters_waiting_hand_ins_together(tmp_path):
    folder = tmp_path / "class"
    folder.mkdir()
    roster, _ = Roster.open(folder, 10)
    clerk = Clerk(folder, roster)
    tokens = [clerk.join(name, None)[1] for name in ("Ann", "Bo", "Cy")]
    batches: list[int] = []
    worker = ClerkThread(clerk, lambda: batches.append(len(clerk.entries)))
    try:
        gate = threading.Event()
        worker.submit(lambda: gate.wait(30))  # the thread busy: what follows waits in its queue
        first = [worker.hand_in(tokens[i], tapped_game(i + 1, player=name).to_bytes())
                 for i, name in enumerate(("Ann", "Bo"))]
        seen = worker.submit(lambda: len(clerk.entries))
        last = worker.hand_in(tokens[2], tapped_game(3, player="Cy").to_bytes())
        failing = worker.submit(lambda: 1 / 0)
        gate.set()
        assert [f.result(30)["name"] for f in first] == ["Ann", "Bo"]
        assert seen.result(30) == 2  # after both hand-ins, before the one that came after it
        assert last.result(30)["name"] == "Cy"
        assert isinstance(failing.exception(30), ZeroDivisionError)  # raised in its request, the thread goes on
        assert worker.submit(lambda: "still here").result(30) == "still here"
    finally:
        worker.stop()
    # after the gate, one batch of two hand-ins (one table write), the job, the last hand-in, the failing job, the
    # last job: the pages' data rebuilt after each, before its answers went out
    assert batches == [0, 2, 2, 3, 3, 3]
