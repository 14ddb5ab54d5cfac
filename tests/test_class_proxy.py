"""The teacher's machine behind a proxy and on a shared PC (issue 54): only the address the proxy appended is
believed, nothing that comes through the proxy is the teacher's, and ``--teacher-secret-always`` makes this machine
type the secret too.

Every machine is its own loopback address (Linux routes the whole of 127.0.0.0/8 to this machine): 127.0.0.1 is
the teacher's own, 127.0.0.2 plays the proxy, and the students behind it are the addresses it names.
"""

from __future__ import annotations

import http.client
import json
import sys

import pytest
from class_server import running_class

from armgame.classroom import client
from armgame.cli import main

pytestmark = pytest.mark.skipif(sys.platform != "linux", reason="other machines are other loopback addresses on Linux")

PROXY, OTHER = "127.0.0.2", "127.0.0.4"


def call(opened, method: str, path: str, headers: dict | None = None, source: str = PROXY, body: bytes | None = None):
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=(source, 0))
    headers = dict(headers or {})
    if method == "POST":
        headers["Content-Type"] = "application/json"
    try:
        conn.request(method, path, body=body, headers=headers)
        response = conn.getresponse()
        data = response.read()
    finally:
        conn.close()
    return response.status, json.loads(data)


def close_class(opened, source: str = PROXY, forwarded: str | list[str] | None = None, secret: str | None = None):
    """/api/teacher/close from ``source`` with the ``X-Forwarded-For`` headers given (None: none); its status."""
    conn = http.client.HTTPConnection("127.0.0.1", opened.port, timeout=10, source_address=(source, 0))
    try:
        conn.putrequest("POST", "/api/teacher/close")
        conn.putheader("Content-Type", "application/json")
        conn.putheader("Content-Length", "2")
        for value in [forwarded] if isinstance(forwarded, str) else forwarded or []:
            conn.putheader("X-Forwarded-For", value)
        if secret is not None:
            conn.putheader("Authorization", f"Bearer {secret}")
        conn.endheaders(b"{}")
        response = conn.getresponse()
        response.read()
    finally:
        conn.close()
    return response.status


@pytest.fixture
def machine(tmp_path, monkeypatch):
    monkeypatch.setenv(client.CLIENT_ENV, str(tmp_path / "machine"))


def test_a_students_own_header_through_the_proxy_is_never_the_teachers_machine(tmp_path, machine):
    """A proxy that passes the client's header on (nginx's default) or appends to it: whatever the student wrote,
    the request is not the teacher's, and only the rightmost entry is the machine counted."""
    lines: list[str] = []
    with running_class(tmp_path / "class", lines=lines, proxy=PROXY) as opened:
        state = opened.server.config.app.state.armgame
        for forwarded in ("127.0.0.1", "::1", "127.0.0.1, 127.0.0.2", ["10.0.0.9", "127.0.0.1"],
                          "10.0.0.9, 127.0.0.1"):
            assert close_class(opened, forwarded=forwarded) == 403, forwarded
            assert not opened.clerk.roster.closed, forwarded
        assert set(state.secrets.seen) == {"127.0.0.1", "::1", "127.0.0.2"}  # the rightmost entry, each time
        for i in range(5):  # wrong codes counted against the machine the proxy named, not the proxy
            call(opened, "POST", "/api/join", {"X-Forwarded-For": f"127.0.0.1, 10.0.0.{i}"},
                 body=json.dumps({"code": "QQQQ", "name": "x"}).encode())
        assert {f"10.0.0.{i}" for i in range(5)} <= set(state.codes.seen)
        # A colleague behind the proxy with the secret, and the teacher's machine reaching the class directly.
        assert close_class(opened, forwarded="10.0.0.7", secret=opened.clerk.roster.secret) == 200
        assert close_class(opened, source="127.0.0.1", forwarded="10.0.0.8") == 200
        assert any("behind the proxy 127.0.0.2" in line for line in lines)


def test_a_proxy_on_this_machine_is_safe_and_a_request_it_names_nobody_for_is_refused(tmp_path, machine):
    """``--proxy 127.0.0.1``: a proxy on the teacher's laptop (TLS in front of the class). A request with no
    X-Forwarded-For is refused (said once in the teacher's terminal); one naming 127.0.0.1 is not the teacher's."""
    lines: list[str] = []
    with running_class(tmp_path / "class", lines=lines, proxy="127.0.0.1") as opened:
        assert close_class(opened, source="127.0.0.1") == 400
        assert close_class(opened, source="127.0.0.1") == 400
        status, answer = call(opened, "GET", "/api/standings", source="127.0.0.1")
        assert status == 400 and "X-Forwarded-For" in answer["error"]
        assert close_class(opened, source="127.0.0.1", forwarded="127.0.0.1") == 403
        assert not opened.clerk.roster.closed
        said = [line for line in lines if "no X-Forwarded-For" in line]
        assert len(said) == 1 and "proxy_set_header X-Forwarded-For" in said[0]
        # The teacher on this laptop types the secret, as on any other machine.
        assert close_class(opened, source="127.0.0.1", forwarded="127.0.0.1", secret=opened.clerk.roster.secret) == 200
        assert opened.clerk.roster.closed


def test_teacher_secret_always_makes_this_machine_type_the_secret(tmp_path, machine):
    lines: list[str] = []
    with running_class(tmp_path / "class", lines=lines, secret_always=True) as opened:
        for _ in range(3):
            assert close_class(opened, source="127.0.0.1") == 403
        status, standings = call(opened, "GET", "/api/standings", source="127.0.0.1")
        assert status == 200 and standings["join"] is None  # nor is the join line shown to it without the key
        assert not opened.clerk.roster.closed
        assert close_class(opened, source="127.0.0.1", secret=opened.clerk.roster.secret) == 200
        assert any("on this machine too: --teacher-secret-always" in line for line in lines)


@pytest.mark.parametrize("proxy", ["*", "10.0.0.0/8", "127.0.0.1,10.0.0.1", "proxy.school"])
def test_proxy_must_be_one_address(tmp_path, capsys, proxy):
    folder = tmp_path / "class"
    assert main(["class", "serve", "--folder", str(folder), "--host", "127.0.0.1", "--port", "0", "--proxy",
                 proxy]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and f"--proxy {proxy}: not an IP address" in err
    assert not folder.exists()


def test_behind_a_proxy_the_students_are_not_one_address_with_one_share():
    """Every student's connection arrives from the proxy: its address has no share of 16 to exceed (the proxy's own
    per-client limits are the share), while any other machine keeps its share."""
    from armgame.classroom.guard import Guard

    guard = Guard(own=frozenset({"127.0.0.1"}), proxy="10.0.0.5", per_address=4)
    assert all(guard.admit("10.0.0.5") for _ in range(40))
    assert [guard.admit("10.0.0.9") for _ in range(5)] == [True] * 4 + [False]
