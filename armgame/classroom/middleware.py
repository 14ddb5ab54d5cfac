"""What every request and every answer of the class passes through, said once.

* ``SecurityHeaders`` (around the whole app): every answer carries ``SECURITY_HEADERS`` (a content
  security policy that allows no inline script, no sniffing, no referrer, nothing cached), the
  router's own 404 and 405 included;
* ``SameSite`` (on each of the class's routes, ``app.ROUTES``): a request the class's own pages or the
  student's client could have sent, else refused (see ``same_site``); a path or a method the class
  does not serve stays the router's own 404 or 405, as it always was;
* ``EXCEPTION_HANDLERS`` (Starlette's ``exception_handlers``): a ``RefusedError`` from any endpoint,
  check or job is its JSON answer (``refusal``); a ``UserError`` (a file the clerk could not write) is
  a 503 in one line with no path of the teacher's machine, and one line in the teacher's terminal;
* ``ForwardedFor`` (inside ``SecurityHeaders``, with ``serve --proxy ADDRESS``): a request whose connection is the
  proxy's is the client the proxy named, the rightmost ``X-Forwarded-For`` entry (see ``forwarded_client``);
* ``OneLineErrors`` (inside ``ForwardedFor``): any other exception is a bug, answered 500 in one
  line, with one line in the teacher's terminal, and the class goes on. Starlette's own handler for
  ``Exception`` (``ServerErrorMiddleware``) would raise it again for the server to print a traceback
  into the terminal the teacher reads the class's code from.

Answers are JSON (``json_answer``): ``{"ok": false, "error": "one line"}`` when refused.
"""

from __future__ import annotations

import functools
import ipaddress
import json
import socket
import sys
from collections.abc import Mapping
from typing import Any

from starlette.datastructures import Headers
from starlette.requests import Request
from starlette.responses import Response
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from ..errors import UserError
from .errors import RefusedError
from .state import FORWARDED

SECURITY_HEADERS = {
    "Content-Security-Policy": "default-src 'none'; script-src 'self'; style-src 'self'; connect-src 'self'; "
                               "img-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'none'",
    "Cross-Origin-Resource-Policy": "same-origin",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-store",
}
_RAW_SECURITY_HEADERS = [(name.lower().encode("latin-1"), value.encode("latin-1"))
                         for name, value in SECURITY_HEADERS.items()]
#: Statuses after which a request's body may be left unread: the connection is closed after the answer.
_BODY_LEFT = (400, 401, 403, 408, 410, 413, 415, 429, 503)


def json_answer(data: object, status: int = 200, headers: Mapping[str, str] | None = None) -> Response:
    """``data`` as the class's JSON (ASCII only, no NaN)."""
    body = json.dumps(data, ensure_ascii=True, allow_nan=False).encode()
    return Response(body, status, headers, media_type="application/json")


def refusal(exc: RefusedError) -> Response:
    """A refusal's answer: its status and its one line; when to come back (429, 503), and the connection closed
    where a body may be left unread."""
    headers = {"Retry-After": str(exc.retry_after)} if exc.status in (429, 503) else {}
    if exc.status in _BODY_LEFT:
        headers["Connection"] = "close"
    return json_answer({"ok": False, "error": exc.message}, exc.status, headers)


async def _refused(request: Request, exc: Exception) -> Response:
    assert isinstance(exc, RefusedError)
    return refusal(exc)


async def _not_written(request: Request, exc: Exception) -> Response:
    """A file the clerk could not write: one line, nothing entered; no path for the room."""
    print(f"armgame class: {request.method} {request.url.path}: {exc}"[:300], file=sys.stderr)
    return refusal(RefusedError(503, "the class could not write this down (the teacher's terminal says why); "
                                     "nothing was entered, and your machine keeps what it sent"))


EXCEPTION_HANDLERS: dict[Any, Any] = {RefusedError: _refused, UserError: _not_written}


class _HTTPMiddleware:
    """Pure ASGI middleware that acts on HTTP requests (``http``) and passes anything else (the lifespan) on."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        await self.http(scope, receive, send)

    async def http(self, scope: Scope, receive: Receive, send: Send) -> None:
        raise NotImplementedError


class SecurityHeaders(_HTTPMiddleware):
    """Pure ASGI middleware: ``SECURITY_HEADERS`` first in every answer's headers (a header an answer sets itself
    is kept as it is)."""

    async def http(self, scope: Scope, receive: Receive, send: Send) -> None:
        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                headers = list(message.get("headers", ()))
                own = {name.lower() for name, _ in headers}
                message["headers"] = [*(h for h in _RAW_SECURITY_HEADERS if h[0] not in own), *headers]
            await send(message)

        await self.app(scope, receive, send_with_headers)


#: What a client is told when the proxy named nobody: the teacher's proxy is set up wrong, no machine told apart.
NO_FORWARDED_FOR = ("the proxy in front of the class sent no X-Forwarded-For, so the class cannot tell its machines "
                    "apart: the teacher's proxy must set it (docs/teaching.md, Behind a proxy)")


def forwarded_client(headers: Headers) -> str | None:
    """The client the proxy names: the rightmost entry of ``X-Forwarded-For`` (of the last such header), the one
    the proxy itself wrote, with nginx's ``$proxy_add_x_forwarded_for`` (which appends) or ``$remote_addr``
    (which replaces); None if there is none or it is not an address. Entries to its left are whatever the client
    sent, and a client can send anything ("127.0.0.1"), so none of them is ever read, and with a proxy that passes
    the client's header on unchanged, the rightmost is the client's word too: the class never takes a forwarded
    address for the teacher's machine (``state.ClassState.teachers_machine``)."""
    values = headers.getlist("x-forwarded-for")
    if not values:
        return None
    last = values[-1].rsplit(",", 1)[-1].strip()
    try:
        return str(ipaddress.ip_address(last))
    except ValueError:
        return None


def _same_address(a: str, b: str) -> bool:
    try:
        return ipaddress.ip_address(a) == ipaddress.ip_address(b)
    except ValueError:
        return False


class ForwardedFor(_HTTPMiddleware):
    """Pure ASGI middleware under ``serve --proxy ADDRESS``: a request whose connection comes from the proxy is the
    client it names (``forwarded_client``), marked ``FORWARDED`` in its scope, so it is never the teacher's machine,
    whatever the header says; one that names nobody is refused in one line (and said once in the teacher's
    terminal), since every machine behind the proxy would share one address's counts. A connection from any other
    address is its socket's address, as without a proxy."""

    def __init__(self, app: ASGIApp, proxy: str | None = None, say: Any = None) -> None:
        super().__init__(app)
        self.proxy = proxy
        self.say = say
        self.said = False

    async def http(self, scope: Scope, receive: Receive, send: Send) -> None:
        client = scope.get("client")
        if self.proxy is None or not client or not _same_address(client[0], self.proxy):
            await self.app(scope, receive, send)
            return
        named = forwarded_client(Headers(scope=scope))
        if named is None:
            if not self.said and self.say is not None:
                self.said = True
                self.say(f"a request came through the proxy {self.proxy} with no X-Forwarded-For: refused (set it "
                         f"in the proxy, e.g. nginx: proxy_set_header X-Forwarded-For $remote_addr;)")
            await refusal(RefusedError(400, NO_FORWARDED_FOR))(scope, receive, send)
            return
        await self.app({**scope, "client": (named, 0), FORWARDED: True}, receive, send)


class OneLineErrors(_HTTPMiddleware):
    """Pure ASGI middleware: an exception no handler answered (a bug) is a 500 in one line, and one line in
    the teacher's terminal; nothing is raised further (the class goes on). After an answer has begun (the
    event stream) there is nothing to answer: the exception goes on to the server."""

    async def http(self, scope: Scope, receive: Receive, send: Send) -> None:
        started = False

        async def sending(message: Message) -> None:
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, receive, sending)
        except Exception as exc:
            if started:
                raise
            request = Request(scope)
            print(f"armgame class: {request.method} {request.url.path}: {type(exc).__name__}: {exc}"[:300],
                  file=sys.stderr)
            await refusal(RefusedError(500, "the class could not take this request (the teacher's terminal says "
                                            "why); nothing was entered"))(scope, receive, send)


class SameSite(_HTTPMiddleware):
    """Pure ASGI middleware on each of the class's routes: ``same_site`` before the endpoint (a refusal goes to
    ``EXCEPTION_HANDLERS`` like any other)."""

    async def http(self, scope: Scope, receive: Receive, send: Send) -> None:
        same_site(scope["method"], Headers(scope=scope))
        await self.app(scope, receive, send)


def same_site(method: str, headers: Headers) -> None:
    """A request the class's own pages or the student's client could have sent; else RefusedError.

    Every request names the class by an address (``Host``), never by a domain name a hostile page could
    point at the class (DNS rebinding); a change (anything but GET) is JSON, which a page on another site
    cannot send without a preflight the class never grants, and its ``Origin`` and ``Sec-Fetch-Site``, where
    sent, are the class's own."""
    if not _named_by_address(headers.get("host", "")):
        raise RefusedError(421, "this class answers at its address only (as printed in the teacher's terminal)")
    if method == "GET":
        return
    media = headers.get("content-type", "").split(";", 1)[0].strip().lower()
    if media != "application/json":
        raise RefusedError(415, "the class takes JSON only (Content-Type: application/json)")
    if headers.get("sec-fetch-site", "same-origin") not in ("same-origin", "none"):
        raise RefusedError(403, "the class takes changes from its own pages only")
    origin = headers.get("origin")
    if origin is not None and origin not in (f"http://{headers.get('host', '')}",
                                             f"https://{headers.get('host', '')}"):
        raise RefusedError(403, "the class takes changes from its own pages only")


@functools.cache
def _own_names() -> frozenset[str]:
    """The names this machine answers to besides its addresses (asked once, not at every request)."""
    host = socket.gethostname().lower()
    return frozenset({"localhost", host, host + ".local"})


def _named_by_address(host: str) -> bool:
    """Whether a ``Host`` header names this server by an address (or localhost), never by a domain name a
    hostile page could point at the class (DNS rebinding)."""
    name = host.rsplit(":", 1)[0] if not host.endswith("]") else host
    name = name.strip("[]").lower()
    if name in _own_names():
        return True
    try:
        ipaddress.ip_address(name)
    except ValueError:
        return False
    return True
